"""Changes of a running tree mission (:class:`~aeroexec.engine.supervision.changes.MissionChange`), planned and made
between two ticks on the engine's thread: the tree document (the model) and the running tree change together, so the
tree stays the one its document builds and a state captured after the change (the flight journal) fits it.

A change is first *planned* (:meth:`TreeChanges.plan`): its targets are found and what it does is written down — the
children it puts in place of others (:class:`Splice`), where sequences go on from (``cursors``), the running nodes it
halts and those it shows SKIPPED — without touching the tree, so that it can be checked like a new mission first
(``aeroexec.trees.change_check``). :meth:`TreeChanges.apply` then makes it: the halted nodes stop their behaviors
(INTERRUPTED: a motion behavior that stops leaves the drone holding its position), the new nodes are built as the
builder builds a document's, each sequence's index is kept on the child it was running (or moved where the change
says), and the mission's node list is rebuilt (:meth:`~aeroexec.trees.runtime.runner.TreeMission.restructure`).

Targets are found by :mod:`.change_targets` (an item number or a node's name). Inserting and
deleting change sequences only; replace and modify any node but the root. A running take-off or landing is never cut
short (:func:`~aeroexec.engine.supervision.changes.not_cut_short`). Inserting before the running item halts it: the
new items fly first, then the item again, from its start. A TML mission's tasks compile into a tree of their own: it
takes skip, and is edited by loading a new mission.

What a change did to the document is kept as plain data (:meth:`ChangePlan.edits`: the tree, the path of the node
whose children changed, the place, the fragment's text or the new port values) in its ``mission_change`` event;
:func:`replay_edits` makes the same edits on the document read again from its file, so a resumed run builds the tree
as it was changed (then puts the captured state back into it).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from aeroexec.engine.catalog.descriptors import RECURRENT
from aeroexec.engine.supervision.changes import ChangeError, MissionChange, not_cut_short
from aeroexec.trees.model import COMMON_ATTRIBUTES, TreeNode
from aeroexec.trees.runtime.builder import TreeBuilder, model_of
from aeroexec.trees.runtime.change_targets import (
    MissionItems,
    ancestors,
    inner,
    is_fallback,
    is_sequence,
    item_of,
    label,
    labels,
    place,
    walk,
)
from aeroexec.trees.runtime.kinds import kind_of, ports_of
from aeroexec.trees.runtime.nodes.behavior_leaves import BehaviorLeaf
from aeroexec.trees.runtime.nodes.controls import Control, Sequence
from aeroexec.trees.runtime.nodes.decorators import Decorator, SubTree
from aeroexec.trees.runtime.nodes.node_conditions import NodeConditions
from aeroexec.trees.runtime.nodes.parallels import Parallel, ParallelAll
from aeroexec.trees.runtime.ticking import FAILURE, INVALID, RUNNING, SUCCESS, attach
from py_trees.behaviour import Behaviour


@dataclass
class Splice:
    """``count`` children of ``parent`` from ``start`` replaced by ``models`` (a model is built; a runtime node is
    kept as it is); ``fragment``, the text the new models were read from (``file``), and ``ports``, the new port
    values of modified models by their offset, say it again as data (:func:`replay_edits`)."""

    parent: Behaviour
    start: int
    count: int
    models: list[TreeNode | Behaviour]
    fragment: str = ""
    ports: dict[int, dict[str, str]] = field(default_factory=dict)

    def children(self, before: list[Any]) -> list[Any]:
        return [*before[:self.start], *self.models, *before[self.start + self.count:]]

    def edit(self, document: Any) -> dict[str, Any]:
        """This splice as data: which node of which tree of ``document``, where, and what is put there."""
        tree, path = _model_path(document, model_of(self.parent))
        files = {m.file for m in self.models if isinstance(m, TreeNode) and not self.ports}
        return {"tree": tree, "path": path, "start": self.start, "count": self.count, "fragment": self.fragment,
                "file": files.pop() if files else "", "ports": {str(k): v for k, v in self.ports.items()}}


@dataclass
class ChangePlan:
    """What a change will do to the running tree (nothing is touched until :meth:`TreeChanges.apply`)."""

    change: MissionChange
    what: str
    splices: list[Splice] = field(default_factory=list)
    cursors: dict[int, tuple[Behaviour, int]] = field(default_factory=dict)  # id(sequence) -> (it, index)
    halted: list[Behaviour] = field(default_factory=list)  # running nodes stopped
    skipped: list[Behaviour] = field(default_factory=list)  # nodes shown SKIPPED
    new: list[TreeNode] = field(default_factory=list)  # the models of the new nodes (checked node by node)

    def edits(self, document: Any) -> list[dict[str, Any]]:
        """What the change does to ``document`` as data (made again by :func:`replay_edits`); before it is made."""
        return [splice.edit(document) for splice in self.splices]

    # -- the tree as it will be (for the check) -------------------------------------------------------------
    def children(self, node: Behaviour) -> list[Any]:
        """``node``'s children after the change: runtime nodes, and models of nodes to be built."""
        children: list[Any] = list(node.children)
        for splice in self.splices:
            if splice.parent is node:
                children = splice.children(children)
        return children

    def index(self, node: Behaviour) -> int | None:
        """Where a sequence goes on from after the change (None: it starts afresh when ticked)."""
        if id(node) in self.cursors:
            return self.cursors[id(node)][1]
        if node.status is not RUNNING and not getattr(node, "index", 0):
            return None
        return self.moved_index(node, getattr(node, "index", 0))

    def moved_index(self, node: Behaviour, index: int) -> int:
        """``index`` in ``node``'s children, moved by the splices in it: the child it named keeps its place; a
        child taken out (or halted by an insertion before it) gives way to what is put at its place."""
        for splice in self.splices:
            if splice.parent is not node:
                continue
            end = splice.start + splice.count
            if end <= index and not (splice.count == 0 and splice.start == index and self.stops(node, index)):
                index += len(splice.models) - splice.count
            elif splice.start <= index:
                index = splice.start
        return index

    def stops(self, node: Behaviour, index: int) -> bool:
        return index < len(node.children) and any(h is node.children[index] for h in self.halted)

    def fresh(self, node: Behaviour) -> bool:
        """True when ``node`` will start afresh (the change halted it, or it was never started)."""
        return any(node is h for h in self.halted) or node.status is INVALID


class TreeChanges:
    """Plans and makes the changes of one running :class:`~aeroexec.trees.runtime.runner.TreeMission`."""

    def __init__(self, mission: Any) -> None:
        self.mission = mission
        self.engine = mission.engine
        self.editable = not callable(getattr(mission.document, "build", None))  # a TML mission builds itself
        self.targets = MissionItems(mission)
        self.span, self.items = self.targets.span, self.targets.items

    # -- planning ------------------------------------------------------------------------------------------
    def plan(self, change: MissionChange, fragment: list[TreeNode] | None = None) -> ChangePlan:
        """What ``change`` would do (``fragment``: the models it inserts or puts in place); :class:`ChangeError`
        says why it cannot be made here."""
        command = change.command
        if command in ("insert", "modify", "delete", "replace") and not self.editable:
            raise ChangeError("a TML mission's tasks compile into a tree of their own: it takes skip; load a new "
                              "mission to change its tasks")
        planner = getattr(self, f"_plan_{command}")
        plan = planner(change, fragment or [])
        for node in plan.halted:
            for leaf in _running_leaves(node):
                why = not_cut_short(self.engine.catalog, leaf.behavior)
                if why:
                    raise ChangeError(why)
        return plan

    def _plan_skip(self, change: MissionChange, _: list[TreeNode]) -> ChangePlan:
        running = [n for n in walk(self.mission.root) if n.status is RUNNING and not n.children]
        behaviors = [n for n in running if isinstance(n, BehaviorLeaf)]
        goals = [n for n in behaviors if getattr(self.engine.catalog.behavior(n.behavior), "category", "") != RECURRENT]
        leaf = next(iter(goals or behaviors or running), None)  # what the mission waits for, not what runs beside
        if leaf is None:
            raise ChangeError("nothing of the mission is running: nothing to skip")
        child, parent = leaf, leaf.parent
        while parent is not None and not (is_sequence(parent) or is_fallback(parent)):
            child, parent = parent, parent.parent
        if parent is None:
            raise ChangeError(f"{leaf.name} is not in a sequence: nothing comes after it to go on with")
        child = next((c for c in parent.children if c is child), child)
        nodes = [child]
        number = item_of(child) if self.targets.plan_items else None
        start = place(parent, child)
        if number is not None:  # a plan's item: every node of it
            while start > 0 and item_of(parent.children[start - 1]) == number:
                start -= 1
            nodes = [parent.children[start]]
            while start + len(nodes) < len(parent.children) and \
                    item_of(parent.children[start + len(nodes)]) == number:
                nodes.append(parent.children[start + len(nodes)])
        end = start + len(nodes)
        skipped = [n for n in nodes if n.status not in (SUCCESS, FAILURE)]
        following = label(parent.children[end]) if end < len(parent.children) else f"what follows {label(parent)}"
        what = f"{' and '.join(label(n) for n in skipped)} skipped; the mission goes on with {following}"
        return ChangePlan(change, what, cursors={id(parent): (parent, end)},
                          halted=[n for n in nodes if n.status is RUNNING], skipped=skipped)

    def _plan_jump(self, change: MissionChange, _: list[TreeNode]) -> ChangePlan:
        _, _, nodes = self.span(change.target)
        target = nodes[0]
        path = [*reversed(ancestors(target)), target]
        plan = ChangePlan(change, f"the mission goes on from {label(target)}")
        for ancestor, child in zip(path, path[1:], strict=False):
            inner = ancestor
            if not _jumps_inside(inner):
                raise ChangeError(f"{label(target)} is inside {label(ancestor)} ({type(ancestor).__name__}), which "
                                  f"chooses for itself what it ticks: jump to {label(ancestor)} instead")
            if not isinstance(inner, Sequence):
                continue
            index = place(inner, child)
            if inner.status is RUNNING and inner.index == index:
                continue
            if inner.status is RUNNING:
                plan.halted += [c for c in inner.children if c.status is RUNNING]
            plan.cursors[id(inner)] = (inner, index)
        if target.status is RUNNING and target not in plan.halted:
            plan.halted.append(target)
        if not plan.cursors and not plan.halted:
            plan.what = f"{label(target)} is where the mission is already"
        return plan

    def _plan_insert(self, change: MissionChange, fragment: list[TreeNode]) -> ChangePlan:
        parent, start, nodes = self.span(change.target)
        self._in_a_sequence(parent, nodes, "inserted into")
        at = start + len(nodes) if change.after else start
        plan = ChangePlan(change, f"{labels(fragment)} inserted {'after' if change.after else 'before'} "
                                  f"{labels(nodes)}", [Splice(parent, at, 0, list(fragment), change.fragment)],
                          new=list(fragment))
        if parent.status is RUNNING and at == parent.index and at < len(parent.children) and \
                parent.children[at].status is RUNNING:
            plan.halted.append(parent.children[at])  # before the running item: the new ones fly first
            plan.what += f" (it is running: it flies again after {labels(fragment)})"
        elif parent.status is RUNNING and at < parent.index:
            plan.what += " (where the mission has already been: it flies only if the mission comes back there)"
        return plan

    def _plan_delete(self, change: MissionChange, _: list[TreeNode]) -> ChangePlan:
        parent, start, nodes = self.span(change.target)
        self._in_a_sequence(parent, nodes, "deleted from")
        if len(nodes) >= len(parent.children):
            raise ChangeError(f"{label(parent)} would be left empty: delete {label(parent)} itself")
        return ChangePlan(change, f"{labels(nodes)} deleted", [Splice(parent, start, len(nodes), [])],
                          halted=[n for n in nodes if n.status is RUNNING])

    def _plan_replace(self, change: MissionChange, fragment: list[TreeNode]) -> ChangePlan:
        parent, start, nodes = self.span(change.target)
        self._editable_here(parent, "replaced in")
        count = len(parent.children) - len(nodes) + len(fragment)
        low, high = parent.manifest.min_children, parent.manifest.max_children
        if count < low or (high is not None and count > high):
            raise ChangeError(f"{label(parent)} ({type(parent).__name__}) cannot have {count} children: replace "
                              f"{label(nodes[0])} with {len(nodes)} node{'s' if len(nodes) != 1 else ''}")
        return ChangePlan(change, f"{labels(nodes)} replaced by {labels(fragment)}",
                          [Splice(parent, start, len(nodes), list(fragment), change.fragment)],
                          halted=[n for n in nodes if n.status is RUNNING], new=list(fragment))

    def _plan_modify(self, change: MissionChange, _: list[TreeNode]) -> ChangePlan:
        parent, start, nodes = self.span(change.target)
        self._editable_here(parent, "modified in")
        ports = dict(change.ports)
        models: list[TreeNode | Behaviour] = []
        used: set[str] = set()
        modified: dict[int, dict[str, str]] = {}
        for offset, node in enumerate(nodes):
            model = model_of(node)
            accepted = {k: v for k, v in ports.items() if len(nodes) == 1 or k in self._ports(model)}
            if not accepted:
                models.append(node)
                continue
            if node.status is RUNNING and inner(node).children:
                raise ChangeError(f"{label(node)} is running: modify the behavior inside it that runs, or replace it")
            used |= set(accepted)
            modified[offset] = accepted
            models.append(_modified(model, accepted))
        unknown = set(ports) - used
        if unknown:
            kinds = ", ".join(dict.fromkeys(model_of(n).type for n in nodes))
            raise ChangeError(f"{labels(nodes)} has no port {', '.join(sorted(unknown))} (its nodes: "
                              f"{kinds})")
        changed = [m for m in models if isinstance(m, TreeNode)]
        what = ", ".join(f"{k}={v}" for k, v in ports.items())
        return ChangePlan(change, f"{labels(nodes)}: {what}", [Splice(parent, start, len(nodes), models,
                                                                      ports=modified)],
                          halted=[n for n, m in zip(nodes, models, strict=True)
                                  if isinstance(m, TreeNode) and n.status is RUNNING], new=changed)

    def _in_a_sequence(self, parent: Behaviour, nodes: list[Behaviour], verb: str) -> None:
        self._editable_here(parent, verb)
        if not is_sequence(parent):
            raise ChangeError(f"items are {verb} sequences; {label(nodes[0])} is in {label(parent)} "
                              f"({type(parent).__name__}): replace {label(parent)} instead")

    def _ports(self, model: TreeNode) -> set[str]:
        descriptor = self.engine.catalog.behavior(model.type)
        declared = set(descriptor.arguments) if descriptor is not None else set(ports_of(model.type))
        aliases = {a for arg in descriptor.arguments.values() for a in arg.aliases} if descriptor is not None else set()
        return declared | aliases | {"name", *COMMON_ATTRIBUTES} - {"ID"}

    def _editable_here(self, parent: Behaviour, verb: str) -> None:
        """Refuse an edit whose model is shared: a parent inside a subtree used more than once, or a SubTree."""
        if isinstance(parent, SubTree):
            raise ChangeError(f"{label(parent)} is a SubTree: replace the SubTree node itself")
        model = model_of(parent)
        if model is None or len(model.children) != len(parent.children):
            raise ChangeError(f"{label(parent)} cannot be changed here (it was not built from the mission's model)")
        for ancestor in [parent, *ancestors(parent)]:
            if isinstance(ancestor, SubTree):
                tree_id = model_of(ancestor).ports.get("ID", "").strip()
                uses = sum(1 for n in walk(self.mission.root)
                           if isinstance(n, SubTree) and model_of(n).ports.get("ID", "").strip() == tree_id)
                if uses > 1:
                    raise ChangeError(f"the tree {tree_id} is used {uses} times: what is {verb} it would change "
                                      f"every use; replace one SubTree node instead")

    # -- making it -------------------------------------------------------------------------------------------
    def apply(self, plan: ChangePlan) -> list[Any]:
        """Make the change; the behaviors it ended (their activations), for a paused supervisor to forget."""
        mission = self.mission
        ended = [leaf.activation for node in plan.halted for leaf in _running_leaves(node)
                 if leaf.activation is not None]
        for node in plan.halted:
            if node.status is RUNNING:
                node.stop(INVALID)
        state = mission.tick_state
        for node in plan.skipped:
            node.status, node.skipped = SUCCESS, True
            state.changed.append(node)
        mission.report()  # the halts and skips, at the places the nodes had
        moved = {id(s.parent): (s.parent, plan.moved_index(s.parent, s.parent.index)) for s in plan.splices
                 if isinstance(s.parent, Sequence)}
        for splice in plan.splices:
            self._splice(splice)
        for node, index in [*moved.values(), *plan.cursors.values()]:
            node.index = index
            node.current_child = node.children[index] if index < len(node.children) else None
        if plan.splices:
            mission.restructure()
        return ended

    def _splice(self, splice: Splice) -> None:
        parent, mission = splice.parent, self.mission
        builder = TreeBuilder(mission.document, mission.context)
        board, stack = self._scope(parent)
        built = [m if isinstance(m, Behaviour) else builder.node(m, board, stack) for m in splice.models]
        for node in built:
            node.parent = parent
            attach(node, mission.tick_state)
        end = splice.start + splice.count
        if isinstance(parent, Decorator):
            parent.decorated = built[0]
            parent.children = [built[0]]
        else:
            parent.children[splice.start:end] = built
        model = model_of(parent)
        model.children[splice.start:end] = [model_of(n) for n in built]
        completed = getattr(parent, "completed", None)
        if isinstance(completed, set):  # a Parallel's completed children, by place
            shift = len(built) - splice.count
            parent.completed = {i if i < splice.start else i + shift for i in completed
                                if not splice.start <= i < end}

    def _scope(self, parent: Behaviour) -> tuple[Any, tuple[str, ...]]:
        """The blackboard ``parent``'s children are built on, and the trees it is inside (for the builder)."""
        board = getattr(getattr(parent, "config", None), "blackboard", None)
        if board is None:
            board = self.mission.blackboard
        trees = [model_of(a).ports.get("ID", "").strip() for a in ancestors(parent) if isinstance(a, SubTree)]
        return board, (self.mission.document.main, *reversed(trees))


# -- the edits, made again on a document ------------------------------------------------------------------------
def replay_edits(document: Any, edits: list[dict[str, Any]], read: Any) -> None:
    """Make ``edits`` (:meth:`ChangePlan.edits`, in the order they were made) on ``document`` as it was read from its
    file: each node's children spliced as the change did; ``read(fragment, file)`` reads a fragment's models
    (``aeroexec.trees.loaders.fragment.read_fragment``). Raises KeyError for an edit that does not fit it."""
    for edit in edits:
        parent = _model_at(document, edit["tree"], edit["path"])
        start, count = int(edit["start"]), int(edit["count"])
        if edit.get("ports"):
            old = parent.children[start:start + count]
            new = [_modified(m, edit["ports"][str(i)]) if str(i) in edit["ports"] else m for i, m in enumerate(old)]
        else:
            new = list(read(edit["fragment"], edit["file"])) if edit.get("fragment") else []
        if start + count > len(parent.children):
            raise KeyError(f"{edit['tree']} {edit['path']}: no children {start} to {start + count}")
        parent.children[start:start + count] = new


def _modified(model: TreeNode, ports: dict[str, str]) -> TreeNode:
    """A copy of ``model`` with new port values (``name`` renames it)."""
    ports = dict(ports)
    name = ports.pop("name", None)
    return dataclasses.replace(model, ports={**model.ports, **ports}, name=name or model.name)


def _model_path(document: Any, model: TreeNode) -> tuple[str, str]:
    """The tree of ``document`` holding ``model`` and the child indexes down to it (``"0.3"``; ``""``: the root)."""
    for tree_id, root in document.trees.items():
        stack: list[tuple[TreeNode, str]] = [(root, "")]
        while stack:
            node, path = stack.pop()
            if node is model:
                return tree_id, path
            stack.extend((child, f"{path}.{i}" if path else str(i)) for i, child in enumerate(node.children))
    raise ChangeError(f"{model.name} is not in the mission's document")


def _model_at(document: Any, tree: str, path: str) -> TreeNode:
    node = document.trees[tree]
    for part in filter(None, path.split(".")):
        node = node.children[int(part)]
    return node


# -- helpers ----------------------------------------------------------------------------------------------------
def _running_leaves(node: Behaviour) -> list[BehaviorLeaf]:
    return [n for n in walk(node) if isinstance(n, BehaviorLeaf) and n.status is RUNNING]


def _jumps_inside(node: Behaviour) -> bool:
    """Whether a jump may land inside ``node``: its kind says (``jumps_inside``); a control node no kind describes
    (a dialect's) only when it is a sequence or a parallel."""
    if isinstance(node, NodeConditions):
        return True
    kind = kind_of(getattr(model_of(node), "type", ""))
    if kind is not None and kind.node_class() is type(node):
        return kind.jumps_inside
    return not isinstance(node, Control) or isinstance(node, (Sequence, Parallel, ParallelAll))


__all__ = ["ChangePlan", "Splice", "TreeChanges", "replay_edits"]
