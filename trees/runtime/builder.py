"""A verified :class:`TreeDocument` as a ``py_trees`` tree that runs on the engine.

Each model node becomes the behaviour of the node kind its type names (``runtime.kinds``, ``nodes.registry``), else a
leaf type the caller registered, else a catalog behavior's leaf; ``source`` is the model node, for file:line in
events. A node with pre- or post-conditions (``_skipIf``, ``_onSuccess``...) is wrapped in
:class:`NodeConditions`, which takes its place in the tree (the wrapped node is marked ``hidden``: the wrapper
shows its status). Each SubTree gets a blackboard of its own, remapped to its parent's as its ports say.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from aeroexec.trees.model import POSTCONDITIONS, PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.context import TreeContext
from aeroexec.trees.runtime.nodes.behavior_leaves import BehaviorLeaf
from aeroexec.trees.runtime.nodes.decorators import SubTree
from aeroexec.trees.runtime.nodes.node_conditions import NodeConditions
from aeroexec.trees.runtime.nodes.registry import node_class
from aeroexec.trees.runtime.ports import NodeConfig, PortError
from aeroexec.trees.script import ScriptError
from py_trees.behaviour import Behaviour

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
        written = [a for a in (*PRECONDITIONS, *POSTCONDITIONS) if model.ports.get(a, "").strip()]
        conditions = {a: self.context.condition(model, a, board) for a in written if a in PRECONDITIONS}
        actions = {a: self.context.action(model, a, board) for a in written if a in POSTCONDITIONS}
        if not conditions and not actions:
            return behaviour
        behaviour.hidden = True  # type: ignore[attr-defined]
        wrapper = NodeConditions(model.name, behaviour, conditions, actions, self.context)
        wrapper.source = model  # type: ignore[attr-defined]
        return wrapper

    def _make(self, model: TreeNode, board: Blackboard, stack: tuple[str, ...]) -> Behaviour:
        kind = model.type
        cls = node_class(kind)
        if cls is SubTree:
            return self._subtree(model, board, stack)
        config = NodeConfig(model, board, self.context)
        if cls is None:
            if kind in self.leaves and not model.children:
                return self.leaves[kind](model, board)
            if kind in self.catalog and not model.children:
                return BehaviorLeaf(model.name, config)
            raise TreeBuildError(f"{model.where}: {kind} cannot be built here (verify the mission first)")
        count = len(model.children)
        low, high = cls.manifest.min_children, cls.manifest.max_children
        if count < low or (high is not None and count > high):
            raise TreeBuildError(f"{model.where}: {kind} cannot have {count} children (verify the mission first)")
        children = [self.node(child, board, stack) for child in model.children]
        try:
            return cls.build(config, children)  # type: ignore[attr-defined]
        except PortError as error:
            raise TreeBuildError(str(error)) from None
        except ScriptError as error:  # a script that does not parse: BT.CPP refuses the tree as it loads
            raise TreeBuildError(f"{model.where}: {kind}: {error}") from None

    def _subtree(self, model: TreeNode, board: Blackboard, stack: tuple[str, ...]) -> Behaviour:
        tree_id = model.ports.get("ID", "").strip()
        root = self.document.trees.get(tree_id)
        if root is None:
            raise TreeBuildError(f"{model.where}: the tree {tree_id} does not exist")
        if tree_id in stack:
            raise TreeBuildError(f"{model.where}: the tree {tree_id} includes itself")
        inner = self.node(root, Blackboard.for_subtree(board, model.ports), (*stack, tree_id))
        return SubTree(model.name, inner, NodeConfig(model, board, self.context))


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
