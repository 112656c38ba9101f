"""The execution engine (paper §4): the loop, its clock and events, and the public surface for embedding it.

``from aeroexec.engine import Engine, BehaviorProcess, ...`` is the documented way in for a robot that embeds the
engine (docs/embedding.md); the names load when first used, so importing the package stays cheap.
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> the module that defines it
PUBLIC = {
    "Engine": "aeroexec.engine.engine",
    "EngineSettings": "aeroexec.engine.execution.process",
    "BehaviorContext": "aeroexec.engine.execution.process",
    "BehaviorLibrary": "aeroexec.engine.execution.process",
    "BehaviorProcess": "aeroexec.engine.execution.process",
    "Situation": "aeroexec.engine.execution.process",
    "Process": "aeroexec.engine.execution.resources",
    "ProcessRegistry": "aeroexec.engine.execution.resources",
    "Outcome": "aeroexec.engine.events",
    "EngineEvent": "aeroexec.engine.events",
    "Clock": "aeroexec.engine.clock",
    "SimulatedClock": "aeroexec.engine.clock",
    "WallClock": "aeroexec.engine.clock",
    "BehaviorCatalog": "aeroexec.engine.catalog",
    "BehaviorSpecialist": "aeroexec.engine.catalog",
    "CatalogError": "aeroexec.engine.catalog",
    "load_catalog": "aeroexec.engine.catalog",
    "RobotKind": "aeroexec.engine.robots",
    "MissionChange": "aeroexec.engine.supervision.changes",
}

__all__ = sorted(PUBLIC)


def __getattr__(name: str) -> Any:
    module = PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'aeroexec.engine' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *PUBLIC])
