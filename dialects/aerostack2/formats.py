"""Aerostack2's mission formats in the core's table (the entry point ``aeroexec.mission_formats``): records only, so
``aeroexec --help``, which lists them, imports nothing of the dialect's readers or checks."""

from __future__ import annotations

from aeroexec.trees.formats import MissionFormat

_HERE = "aeroexec.dialects.aerostack2"
FORMATS = (
    MissionFormat("Aerostack2 interpreter plans", (".json", ".yaml", ".yml"), f"{_HERE}.plans:read_plan_tree",
                  recognise=f"{_HERE}.plans:is_aerostack2_plan",
                  summary="Aerostack2's mission interpreter plans ({target, plan})", before="Aerostack nodes: YAML"),
)

__all__ = ["FORMATS"]
