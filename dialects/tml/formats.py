"""TML's mission formats in the core's table (the entry point ``aeroexec.mission_formats``): records only, so
``aeroexec --help``, which lists them, imports nothing of the dialect's readers or checks."""

from __future__ import annotations

from aeroexec.trees.formats import MissionFormat

FORMATS = (
    MissionFormat("TML", (".tml.xml",), "aeroexec.trees.mission_file:read_xml_tree", summary="a TML mission",
                  before="BehaviorTree.CPP XML"),
)

__all__ = ["FORMATS"]
