"""The node kinds of a behavior tree, one descriptor each (:class:`NodeKind`): what every pass asks of a node.

A node kind is its XML name with its manifest (kind, ports, children, loops: ``manifests``), the class that runs it
(``module:Class``, imported the first time a tree is built: verification needs no py_trees), what it remembers
between ticks (a resumed run puts it back: ``tree_state``), how the WRONG_SEQUENCE check follows it (``flow``), how
the route estimate goes through it (``route``), whether a live change may jump inside it (``jumps_inside``), and how
BehaviorTree.CPP's ``.btlog`` logs it (``btlog``). The checkers walk the tree and ask the kind; none of them names a
node. :data:`BUILT_IN` holds the built-in kinds; other packages add theirs with an entry point in the group
``aeroexec.node_kinds`` naming a :class:`NodeKind` (or a list of them): :func:`kinds` is both.

The words of ``flow`` (read by ``trees.sequence_check``):

- ``sequence``, ``sequence_with_memory``, ``reactive_sequence``, ``fallback``, ``reactive_fallback``,
  ``parallel``, ``if_then_else``, ``while_do_else``: the control nodes of those names' semantics;
- ``decorator`` (its child's exits), ``invert``, ``force_success``, ``force_failure``, ``repeat``, ``retry``,
  ``keep_running_until_failure``, ``run_once``: a decorator;
- ``subtree``: the tree its ``ID`` names; ``ask``: the catalog behavior its ``behavior_port`` names;
- ``consult``: a leaf reading beliefs (its ``belief`` port): the phenomena they are named after become unknown;
- ``pass`` (succeeds or fails, changing nothing), ``succeed``, ``fail``: a leaf that changes no phenomenon;
- ``opaque`` (what a kind says nothing of): whatever the behaviors below it change becomes unknown.

The words of ``route`` (read by ``trees.route``): ``series`` (its children in order), ``repeat`` (its child
``num_cycles`` times), ``parallel`` (its one flying child; the others run beside it) and ``""``: no route.
"""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass

from aeroexec.trees.runtime.manifests import CONTROL, DECORATOR, MANIFESTS, SUBTREE, NodeManifest, Port

from aeroexec.plugins import installed_plugins, load_reference

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

ENTRY_POINT_GROUP = "aeroexec.node_kinds"
#: The words of ``flow`` and ``route`` (see the module).
FLOWS = ("sequence", "sequence_with_memory", "reactive_sequence", "fallback", "reactive_fallback", "parallel",
         "if_then_else", "while_do_else", "decorator", "invert", "force_success", "force_failure", "repeat", "retry",
         "keep_running_until_failure", "run_once", "subtree", "ask", "consult", "pass", "succeed", "fail", "opaque")
ROUTES = ("", "series", "repeat", "parallel")


@dataclass(frozen=True, slots=True)
class Btlog:
    """How BehaviorTree.CPP logs a node's statuses in a ``.btlog`` (``trees.groot.btlog``).

    ``running``: when the node goes RUNNING as it is ticked (``tick``: every tick, as control nodes and most
    decorators; ``idle``: only when ticked from IDLE; ``""``: its own result says). ``resets_child``: a child that
    completes goes back to IDLE at once (a decorator). ``halts_others``: every child but the running one is reset
    (a reactive node). ``keeps_succeeded``: on FAILURE the children that succeeded keep their status (a sequence
    with memory). ``other_branch``: the branch not taken is reset before the other ticks (WhileDoElse).
    ``bare_condition``: a failed condition without an else resets nothing (IfThenElse)."""

    running: str = ""
    resets_child: bool = False
    halts_others: bool = False
    keeps_succeeded: bool = False
    other_branch: bool = False
    bare_condition: bool = False


_LEAF_LOG = Btlog()
_CONTROL_LOG = Btlog("tick")
_DECORATOR_LOG = Btlog("tick", resets_child=True)
_FROM_IDLE_LOG = Btlog("idle", resets_child=True)


@dataclass(frozen=True)
class NodeKind:
    """One node kind, as every pass asks it (see the module): name, manifest, runtime class, memory, flow, route,
    change rule, ``.btlog`` rule, the port naming the catalog behavior it runs (AskBehavior's ``behavior``) and the
    ports that count its children (Parallel's), whether its children run together, and the bidirectional ports it
    only writes. What its ports' texts are written in is the manifest's (``Port``'s
    ``language``: scripts, belief expressions, rules), which verification checks."""

    name: str
    manifest: NodeManifest
    runtime: str  # "module:Class": the py_trees behaviour that runs it, imported when a tree is built
    memory: tuple[str, ...] = ()  # attributes it remembers between ticks (kept by tree_state)
    flow: str = ""  # the sequence check's word (default: "decorator" for a decorator, else "opaque")
    route: str = ""  # the route estimate's word ("" : a tree with this node has no route)
    btlog: Btlog | None = None  # default: by the manifest's kind
    jumps_inside: bool = True  # a live change may jump to a node inside it (False: it chooses what it ticks)
    behavior_port: str = ""  # the port naming the catalog behavior it runs
    counts_children: tuple[str, ...] = ()  # ports counting its children (negative n: all but -1 - n), checked
    concurrent: bool = False  # its children run together (the blackboard check: no order among their writes)
    writes_only: tuple[str, ...] = ()  # bidirectional ports it only writes (SetBlackboard's output_key)
    origin: str = "aeroexec"  # the package that adds it

    def __post_init__(self) -> None:
        if not self.flow:
            object.__setattr__(self, "flow", "decorator" if self.manifest.kind == DECORATOR else "opaque")
        if self.btlog is None:
            by_kind = {CONTROL: _CONTROL_LOG, DECORATOR: _DECORATOR_LOG, SUBTREE: _FROM_IDLE_LOG}
            object.__setattr__(self, "btlog", by_kind.get(self.manifest.kind, _LEAF_LOG))
        if self.flow not in FLOWS:
            raise ValueError(f"the node kind {self.name}: flow {self.flow!r} is none of {', '.join(FLOWS)}")
        if self.route not in ROUTES:
            raise ValueError(f"the node kind {self.name}: route {self.route!r} is none of {', '.join(ROUTES[1:])}")

    @property
    def subtree(self) -> bool:
        """A node whose child is the tree its ``ID`` names."""
        return self.manifest.kind == SUBTREE

    @property
    def loops(self) -> bool:
        return self.manifest.loops

    @property
    def ports(self) -> dict[str, Port]:
        return {port.name: port for port in self.manifest.ports}

    def ports_in(self, *languages: str) -> tuple[str, ...]:
        """Its ports written in one of ``languages`` (``Port.language``: script, belief, query, new_belief, rules)."""
        return tuple(port.name for port in self.manifest.ports if port.language in languages)

    @property
    def class_name(self) -> str:
        return self.runtime.rpartition(":")[2].rpartition(".")[2]

    def node_class(self) -> Any:
        """The class that runs the kind (imported now, once)."""
        return _load(self.runtime)


@functools.cache
def _load(reference: str) -> Any:
    return load_reference(reference)


_NODES = "aeroexec.trees.runtime.nodes"
_SEQUENCE_MEMORY = ("index", "skipped_count")


def _kind(name: str, module: str, **described: Any) -> NodeKind:
    return NodeKind(name, MANIFESTS[name], f"{_NODES}.{module}:{name}", **described)


#: The built-in kinds: BehaviorTree.CPP's nodes and the engine's leaves (a catalog behavior is no kind: its leaf is
#: ``behavior_leaves.BehaviorLeaf``, its meaning the catalog's).
BUILT_IN: tuple[NodeKind, ...] = (
    # controls
    _kind("Sequence", "controls", memory=_SEQUENCE_MEMORY, flow="sequence", route="series"),
    _kind("SequenceWithMemory", "controls", memory=_SEQUENCE_MEMORY, flow="sequence_with_memory", route="series",
          btlog=Btlog("tick", keeps_succeeded=True)),
    _kind("AsyncSequence", "controls", memory=_SEQUENCE_MEMORY),
    _kind("ReactiveSequence", "controls", flow="reactive_sequence", jumps_inside=False,
          btlog=Btlog("tick", halts_others=True)),
    _kind("Fallback", "controls", memory=_SEQUENCE_MEMORY, flow="fallback"),
    _kind("AsyncFallback", "controls", memory=_SEQUENCE_MEMORY),
    _kind("ReactiveFallback", "controls", flow="reactive_fallback", jumps_inside=False,
          btlog=Btlog("tick", halts_others=True)),
    _kind("Parallel", "parallels", memory=("completed", "successes", "failures"), flow="parallel", route="parallel",
          counts_children=("success_count", "failure_count"), concurrent=True),
    _kind("ParallelAll", "parallels", memory=("completed", "failures"), concurrent=True),
    _kind("IfThenElse", "branches", memory=("branch",), flow="if_then_else", jumps_inside=False,
          btlog=Btlog("tick", bare_condition=True)),
    _kind("WhileDoElse", "branches", flow="while_do_else", jumps_inside=False, btlog=Btlog("tick", other_branch=True)),
    *(_kind(f"Switch{cases}", "branches", memory=("running",), jumps_inside=False) for cases in range(2, 7)),
    _kind("TryCatch", "branches", memory=(*_SEQUENCE_MEMORY, "catching"), jumps_inside=False),
    # decorators
    _kind("Inverter", "decorators", flow="invert"),
    _kind("ForceSuccess", "decorators", flow="force_success"),
    _kind("ForceFailure", "decorators", flow="force_failure"),
    _kind("Repeat", "decorators", memory=("count",), flow="repeat", route="repeat"),
    _kind("RetryUntilSuccessful", "decorators", memory=("count",), flow="retry"),
    _kind("KeepRunningUntilFailure", "decorators", flow="keep_running_until_failure"),
    _kind("Timeout", "decorators", memory=("seconds", "started_at"), btlog=_FROM_IDLE_LOG),
    _kind("Delay", "decorators", memory=("seconds", "started_at"), btlog=_FROM_IDLE_LOG),
    _kind("RunOnce", "decorators", memory=("first",), flow="run_once"),
    _kind("Precondition", "decorators", memory=("running",)),
    *(_kind(f"Loop{item}", "decorators", memory=("queue", "child_running")) for item in ("Int", "Double", "String",
                                                                                        "Bool")),
    _kind("SkipUnlessUpdated", "decorators", memory=("seen", "executing")),
    _kind("WaitValueUpdate", "decorators", memory=("seen", "executing")),
    _kind("SubTree", "decorators", flow="subtree"),
    # actions and conditions
    _kind("AlwaysSuccess", "actions", flow="succeed"),
    _kind("AlwaysFailure", "actions", flow="fail"),
    _kind("Script", "actions"),
    _kind("ScriptCondition", "actions"),
    _kind("SetBlackboard", "actions", writes_only=("output_key",)),
    _kind("UnsetBlackboard", "actions"),
    _kind("Sleep", "actions", memory=("seconds", "started_at")),
    _kind("WasEntryUpdated", "actions", memory=("seen",)),
    # the engine's leaves
    _kind("AskBehavior", "behavior_leaves", flow="ask", behavior_port="behavior"),
    _kind("CheckBelief", "belief_leaves", flow="consult"),
    _kind("Condition", "belief_leaves", flow="consult"),
    _kind("QueryBelief", "belief_leaves", flow="consult"),
    _kind("AddBelief", "belief_leaves", flow="pass"),
    _kind("RemoveBelief", "belief_leaves", flow="pass"),
    # its rules are the memory's: a resume adds them again (flight/journal/resumption.py)
    _kind("AddRule", "belief_leaves", memory=("added",)),
)


_BUILT_IN_NAMES = frozenset(kind.name for kind in BUILT_IN)


@functools.cache
def kinds() -> dict[str, NodeKind]:
    """Every node kind by name: the built-in ones, then those of the installed ``aeroexec.node_kinds`` entry points
    (one whose name is taken already is refused, and logged)."""
    found = {kind.name: kind for kind in BUILT_IN}
    for origin, provided in installed_plugins(ENTRY_POINT_GROUP):
        for kind in [provided] if isinstance(provided, NodeKind) else list(provided or ()):
            if not isinstance(kind, NodeKind):
                logger.error("%s is not a NodeKind: %r", origin, kind)
            elif kind.name in found:
                logger.error("%s: the node kind %s exists already", origin, kind.name)
            else:
                found[kind.name] = kind
    return found


def kind_of(name: str) -> NodeKind | None:
    """The node kind named ``name`` (None: a catalog behavior, or no node at all)."""
    return kinds().get(name)


def ports_of(name: str) -> dict[str, Port]:
    """The ports a node kind declares, by name (empty for any other node)."""
    kind = kinds().get(name)
    return kind.ports if kind is not None else {}


def added() -> list[NodeKind]:
    """The node kinds other packages add (for the help texts and the Groot2 palette)."""
    return [kind for kind in kinds().values() if kind.name not in _BUILT_IN_NAMES]


def is_subtree(name: str) -> bool:
    """Whether a node named ``name`` is a SubTree: its child is the tree its ``ID`` names."""
    kind = kinds().get(name)
    return kind is not None and kind.subtree


def ports_in(name: str, *languages: str) -> tuple[str, ...]:
    """The ports of the node kind ``name`` written in one of ``languages`` (none for any other node)."""
    kind = kinds().get(name)
    return kind.ports_in(*languages) if kind is not None else ()


def memory_by_class() -> dict[str, tuple[str, ...]]:
    """What each kind's class remembers, by class name (``tree_state`` looks a class's up along its bases)."""
    return {kind.class_name: kind.memory for kind in kinds().values() if kind.memory}


__all__ = ["BUILT_IN", "ENTRY_POINT_GROUP", "FLOWS", "ROUTES", "Btlog", "NodeKind", "added", "is_subtree", "kind_of",
           "kinds", "memory_by_class", "ports_in", "ports_of"]
