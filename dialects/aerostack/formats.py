"""Aerostack's mission formats in the core's table (the entry point ``aeroexec.mission_formats``): records only, so
``aeroexec --help``, which lists them, imports nothing of the dialect's readers or checks."""

from __future__ import annotations

from aeroexec.trees.formats import MissionFormat

_HERE = "aeroexec.dialects.aerostack"
FORMATS = (
    MissionFormat("Aerostack nodes: YAML", (".yaml", ".yml"), "aeroexec.trees.mission_file:read_yaml_tree",
                  recognise=f"{_HERE}.nodes:is_aerostack_nodes", summary="Aerostack's behavior tree interpreter nodes:",
                  before="YAML trees"),
)

__all__ = ["FORMATS"]
