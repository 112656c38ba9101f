"""A verified :class:`TreeDocument` as a ``py_trees`` tree that runs on the engine.

Each model node becomes one behaviour (``source`` is the model node, for file:line in events). A node with
``_failureIf``/``_successIf``/``_skipIf``/``_while`` is wrapped in a :class:`Preconditions` decorator that takes
its place in the tree (the wrapped node is marked ``hidden``: the wrapper shows its status). Each SubTree gets a
blackboard of its own, remapped to its parent's as its ports say.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.node_types import CONTROL_TYPES, POSTCONDITIONS, PRECONDITIONS, bare_key
from aeroexec.trees.ports import parse_number
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.control import SKIPPED, make_control
from aeroexec.trees.runtime.decorators import (
    Delay,
    Force,
    Inverter,
    KeepRunningUntilFailure,
    Loop,
    PassThrough,
    Preconditions,
    RunOnce,
    Timeout,
)
from aeroexec.trees.runtime.nodes import AskBehaviorLeaf, BehaviorLeaf, BeliefLeaf, Constant, RuleLeaf, TreeContext
from aeroexec.trees.runtime.script_nodes import Precondition, ScriptLeaf, SetBlackboard, Switch, UnsetBlackboard
from aeroexec.trees.runtime.v4_nodes import LOOP_TYPES, EntryUpdated, ParallelAll, Sleep, TryCatch, WasEntryUpdated
from aeroexec.trees.runtime.v4_nodes import Loop as V4Loop
from py_trees.behaviour import Behaviour
from py_trees.common import Status

BELIEF_LEAVES = ("Condition", "CheckBelief", "QueryBelief", "AddBelief", "RemoveBelief")
#: A leaf type registered by the caller, as BehaviorTree.CPP's factory registers nodes: model node, blackboard -> leaf.
LeafFactory = Callable[[TreeNode, Blackboard], Behaviour]


class TreeBuildError(ValueError):
    """A document that cannot be built (verify it first: verification reports this and more, with places)."""


class TreeBuilder:
    """Builds the py_trees behaviours of one document for one run."""

    def __init__(self, document: TreeDocument, context: TreeContext,
                 leaves: Mapping[str, LeafFactory] | None = None) -> None:
        self.document = document
        self.context = context
        self.catalog = context.engine.catalog
        self.leaves = dict(leaves or {})

    def build(self, blackboard: Blackboard) -> Behaviour:
        return self.node(self.document.root, blackboard, (self.document.main,))

    def node(self, model: TreeNode, board: Blackboard, stack: tuple[str, ...]) -> Behaviour:
        behaviour = self._make(model, board, stack)
        behaviour.source = model  # type: ignore[attr-defined]
        conditions = {a: self.context.condition(model.ports[a], board, f"{model.where} {a}")
                      for a in PRECONDITIONS if model.ports.get(a, "").strip()}
        actions = {a: self.context.action(model.ports[a], board, f"{model.where} {a}")
                   for a in POSTCONDITIONS if model.ports.get(a, "").strip()}
        if not conditions and not actions:
            return behaviour
        behaviour.hidden = True  # type: ignore[attr-defined]
        wrapper = Preconditions(model.name, behaviour, conditions, actions)
        wrapper.source = model  # type: ignore[attr-defined]
        return wrapper

    def _make(self, model: TreeNode, board: Blackboard, stack: tuple[str, ...]) -> Behaviour:
        kind, name, ports = model.type, model.name, model.ports
        if kind == "SubTree":
            return self._subtree(model, board, stack)
        children = [self.node(child, board, stack) for child in model.children]
        if kind == "ParallelAll":
            return ParallelAll(name, children, self._integer(model, "max_failures", default=1))
        if kind == "TryCatch":
            return TryCatch(name, children, ports.get("catch_on_halt", "false").strip().lower() == "true")
        if kind in LOOP_TYPES and len(children) == 1:
            return V4Loop(name, children[0], kind, ports, board)
        if kind in ("SkipUnlessUpdated", "WaitValueUpdate") and len(children) == 1:
            return EntryUpdated(name, children[0], ports.get("entry", ""), board,
                                SKIPPED if kind == "SkipUnlessUpdated" else Status.RUNNING)
        if kind == "WasEntryUpdated":
            return WasEntryUpdated(name, ports.get("entry", ""), self.context, board, model)
        if kind == "Sleep":
            return Sleep(name, self._integer(model, "msec") / 1000.0, self.context, board, model)
        if kind.startswith("Switch") and kind in CONTROL_TYPES:
            return Switch(name, children, ports, board)
        if kind == "Precondition" and len(children) == 1:
            return Precondition(name, children[0], ports.get("if", ""), ports.get("else", "FAILURE"), board,
                                self.context)
        if kind in CONTROL_TYPES:
            typed = {k: self._integer(model, k) for k in ("success_count", "failure_count") if k in ports}
            return make_control(kind, name, children, typed)
        if children:
            decorator = self._decorator(model, children, board)
            if decorator is not None:
                return decorator
        if kind in ("Script", "ScriptCondition"):
            return ScriptLeaf(name, ports.get("code", ""), kind == "ScriptCondition", self.context, board, model)
        if kind == "SetBlackboard":
            return SetBlackboard(name, ports, self.context, board, model)
        if kind == "UnsetBlackboard":
            return UnsetBlackboard(name, ports.get("key", ""), self.context, board, model)
        if kind == "AlwaysSuccess":
            return Constant(name, Status.SUCCESS, self.context, board, model)
        if kind == "AlwaysFailure":
            return Constant(name, Status.FAILURE, self.context, board, model)
        if kind in BELIEF_LEAVES:
            leaf = BeliefLeaf(name, kind, ports.get("belief", ""), self.context, board, model)
            leaf.multivalued = ports.get("multivalued", "false").strip().lower() in ("true", "1", "yes")
            return leaf
        if kind == "AskBehavior":
            return AskBehaviorLeaf(name, ports, self.context, board, model)
        if kind == "AddRule":
            return RuleLeaf(name, ports.get("rule", ""), self.context, board, model)
        if kind in self.leaves and not model.children:
            return self.leaves[kind](model, board)
        if kind in self.catalog and not model.children:
            return BehaviorLeaf(name, kind, ports, self.context, board, model)
        raise TreeBuildError(f"{model.where}: {kind} cannot be built here (verify the mission first)")

    def _decorator(self, model: TreeNode, children: list[Behaviour], board: Blackboard) -> Behaviour | None:
        kind, name, child = model.type, model.name, children[0]
        if len(children) != 1:
            return None
        clock = self.context.now
        if kind == "Inverter":
            return Inverter(name, child)
        if kind in ("ForceSuccess", "ForceFailure"):
            return Force(name, child, Status.SUCCESS if kind == "ForceSuccess" else Status.FAILURE)
        if kind == "Repeat":
            return Loop(name, child, self._count(model, "num_cycles", board), retry=False)
        if kind == "RetryUntilSuccessful":
            return Loop(name, child, self._count(model, "num_attempts", board), retry=True)
        if kind == "KeepRunningUntilFailure":
            return KeepRunningUntilFailure(name, child)
        if kind == "Timeout":
            return Timeout(name, child, self._integer(model, "msec") / 1000.0, clock)
        if kind == "Delay":
            return Delay(name, child, self._integer(model, "delay_msec") / 1000.0, clock)
        if kind == "RunOnce":
            skip = model.ports.get("then_skip", "true").strip().lower() not in ("false", "0", "no")
            return RunOnce(name, child, skip)
        return None

    def _subtree(self, model: TreeNode, board: Blackboard, stack: tuple[str, ...]) -> Behaviour:
        tree_id = model.ports.get("ID", "").strip()
        root = self.document.trees.get(tree_id)
        if root is None:
            raise TreeBuildError(f"{model.where}: the tree {tree_id} does not exist")
        if tree_id in stack:
            raise TreeBuildError(f"{model.where}: the tree {tree_id} includes itself")
        inner = self.node(root, Blackboard.for_subtree(board, model.ports), (*stack, tree_id))
        return PassThrough(model.name, inner)

    def _count(self, model: TreeNode, port: str, board: Blackboard) -> int | Callable[[], int]:
        """An integer port, or a function reading it from the blackboard when it is written ``{key}``."""
        key = bare_key(model.ports.get(port, ""))
        if key is None:
            return self._integer(model, port)

        def read() -> int:
            value = board.get(key)
            number = parse_number(str(value)) if value is not None else None
            if not isinstance(number, int | float) or number != int(number):
                raise TreeBuildError(f"{model.where}: {model.type} needs an integer {port}, and {{{key}}} is "
                                     f"{value!r}")
            return int(number)

        return read

    @staticmethod
    def _integer(model: TreeNode, port: str, default: int | None = None) -> int:
        if default is not None and not model.ports.get(port, "").strip():
            return default
        value = parse_number(model.ports.get(port, ""))
        if not isinstance(value, int):
            raise TreeBuildError(f"{model.where}: {model.type} needs an integer {port}, not "
                                 f"{model.ports.get(port, '(none)')!r}")
        return value


def build_tree(document: TreeDocument, context: TreeContext, blackboard: Blackboard | None = None,
               leaves: Mapping[str, LeafFactory] | None = None) -> Behaviour:
    """The py_trees root of ``document``'s main tree for a run in ``context`` (``leaves``: extra leaf types).

    A document with a ``build(context, blackboard)`` method builds itself (a TML mission: see ``trees.tml_compile``).
    """
    board = blackboard if blackboard is not None else Blackboard()
    build = getattr(document, "build", None)
    if callable(build):
        return build(context, board)
    return TreeBuilder(document, context, leaves).build(board)


def describe(root: Behaviour) -> list[tuple[int, Behaviour]]:
    """Every visible node with its depth, in document order (for the terminal and status events)."""
    found: list[tuple[int, Behaviour]] = []

    def walk(node: Behaviour, depth: int) -> None:
        hidden = getattr(node, "hidden", False)
        if not hidden:
            found.append((depth, node))
        for child in node.children:
            walk(child, depth if hidden else depth + 1)

    walk(root, 0)
    return found


def model_of(node: Behaviour) -> Any:
    return getattr(node, "source", None)
