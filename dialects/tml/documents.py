"""TML as the core's XML reader and tree checks ask for it (the entry points ``aeroexec.xml_documents`` and
``aeroexec.tree_verifiers``): every XML mission is handed to both, and only a TML mission imports the dialect's
reader, compiler and checks (~8 ms of ``aeroexec verify`` of a behavior tree, ``bench/startup.py``)."""

from __future__ import annotations

import sys

TYPE_CHECKING = False  # typing is not imported at run time
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.dialects.tml.compiler import TmlDocument
    from aeroexec.engine.catalog import BehaviorCatalog
    from aeroexec.engine.catalog.world_check import WorldMap
    from aeroexec.engine.errors import Problem
    from aeroexec.trees.model import TreeDocument

_COMPILER = "aeroexec.dialects.tml.compiler"


def read_tml_element(root: Any, raw: bytes, file: str, lenient: list[tuple[str, int, str]]) -> TmlDocument | None:
    """The TML mission of an XML document (:func:`.compiler.read_tml_element`); None, without importing the
    dialect, when its document element is not TML's ``<mission>``."""
    if root.tag != "mission":
        return None
    from aeroexec.dialects.tml.compiler import read_tml_element as read  # here: only a <mission> may be TML

    return read(root, raw, file, lenient)


def verify_tml_document(document: TreeDocument, catalog: BehaviorCatalog | None = None,
                        world: WorldMap | None = None) -> list[Problem] | None:
    """Every problem of a TML mission (:func:`.verify.verify_tml_document`); None for any other document, without
    importing the dialect's checks: a TML mission is compiled by its compiler, so none exists before it is imported."""
    compiler = sys.modules.get(_COMPILER)
    if compiler is None or not isinstance(document, compiler.TmlDocument):
        return None
    from aeroexec.dialects.tml.verify import verify_tml_document as verify  # here: only a TML mission

    return verify(document, catalog, world)


__all__ = ["read_tml_element", "verify_tml_document"]
