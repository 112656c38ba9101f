"""The built-in nodes' classes by XML name (BehaviorTree.CPP's factory of built-ins), read from the one table of node
kinds (``trees.runtime.kinds``: each kind's ``runtime`` class, manifest, memory, flow...).

A new built-in node is its manifest in ``manifests`` (its kind, ports, children, whether it loops), one class in the
module of its kind (``controls``, ``parallels``, ``branches``, ``decorators``, ``actions``, ``behavior_leaves``,
``belief_leaves``) that takes it (``manifest = MANIFESTS["Name"]``), and one ``NodeKind`` in ``kinds.BUILT_IN``.
The builder makes every node through :func:`node_class`; verification reads the kinds alone (no py_trees). A
catalog behavior name is a leaf type of its own (``BehaviorLeaf``).
"""

from __future__ import annotations

from aeroexec.trees.runtime.kinds import BUILT_IN as BUILT_IN_KINDS
from aeroexec.trees.runtime.kinds import kind_of
from aeroexec.trees.runtime.ticking import Node

BUILT_IN: dict[str, type[Node]] = {kind.name: kind.node_class() for kind in BUILT_IN_KINDS}
"""The built-in nodes' classes by XML name."""


def node_class(name: str) -> type[Node] | None:
    """The class of the node kind ``name`` (built-in, or added by a package), None for any other name."""
    found = BUILT_IN.get(name)
    if found is None:
        kind = kind_of(name)
        found = kind.node_class() if kind is not None else None
    return found


__all__ = ["BUILT_IN", "node_class"]
