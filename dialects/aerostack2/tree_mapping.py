"""Aerostack2's tree mapping as the core asks for it (the ``aeroexec.tree_mappings`` entry point): every XML
mission is handed to it, and only one that uses Aerostack2's nodes imports the mapping (:mod:`.tree_nodes`)."""

from __future__ import annotations

from aeroexec.dialects.aerostack2.node_ports import is_aerostack2

TYPE_CHECKING = False  # typing is not imported at run time
if TYPE_CHECKING:
    from aeroexec.drones.geodesy import Geodetic
    from aeroexec.trees.model import TreeDocument


def mapped_tree(document: TreeDocument, home: Geodetic | None = None) -> TreeDocument:
    """The document with Aerostack2's nodes mapped onto the catalog (:func:`.tree_nodes.aerostack2_tree`), itself
    when it uses none."""
    if not is_aerostack2(document):
        return document
    from aeroexec.dialects.aerostack2.tree_nodes import aerostack2_tree  # here: only a document that uses them

    return aerostack2_tree(document, home)


__all__ = ["mapped_tree"]
