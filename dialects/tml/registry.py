"""TML registered with the core, as another package would be (pyproject.toml's entry points): its ``.tml.xml``
files in the table of mission formats, read by the core's XML reader, which hands a document whose element is TML's
``<mission>`` to :func:`.compiler.read_tml_element` (the entry-point group ``aeroexec.xml_documents``); a compiled
mission builds and verifies itself (:class:`.compiler.TmlDocument`)."""

from __future__ import annotations

from aeroexec.trees.formats import MissionFormat

FORMATS = (
    MissionFormat("TML", (".tml.xml",), "aeroexec.trees.mission_file:read_xml_tree", summary="a TML mission",
                  before="BehaviorTree.CPP XML"),
)

__all__ = ["FORMATS"]
