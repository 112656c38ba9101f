"""The execution engine (paper §4): the loop, its clock and events, and the public surface for embedding it.

``from aeroexec.engine import Engine, BehaviorProcess, ...`` is the documented way in for a robot that embeds the
engine (docs/embedding.md); the names load when first used, so importing the package stays cheap.
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["BehaviorCatalog", "BehaviorContext", "BehaviorLibrary", "BehaviorProcess", "BehaviorSpecialist",
           "CatalogError", "Clock", "Engine", "EngineEvent", "EngineSettings", "MissionChange", "Outcome", "Process",
           "ProcessRegistry", "RobotKind", "SimulatedClock", "Situation", "WallClock", "load_catalog"]
__getattr__ = lazy_names(__name__, {"BehaviorCatalog": "catalog.behavior_catalog",
                                    "CatalogError": "catalog.behavior_catalog",
                                    "load_catalog": "catalog.behavior_catalog",
                                    "BehaviorSpecialist": "catalog.specialist", "Clock": "clock",
                                    "SimulatedClock": "clock", "WallClock": "clock", "Engine": "engine",
                                    "EngineEvent": "events", "Outcome": "events",
                                    "BehaviorContext": "execution.process", "BehaviorLibrary": "execution.process",
                                    "BehaviorProcess": "execution.process", "EngineSettings": "execution.process",
                                    "Situation": "execution.process", "Process": "execution.resources",
                                    "ProcessRegistry": "execution.resources", "RobotKind": "robots",
                                    "MissionChange": "supervision.changes"})

if TYPE_CHECKING:
    from aeroexec.engine.catalog.behavior_catalog import BehaviorCatalog, CatalogError, load_catalog
    from aeroexec.engine.catalog.specialist import BehaviorSpecialist
    from aeroexec.engine.clock import Clock, SimulatedClock, WallClock
    from aeroexec.engine.engine import Engine
    from aeroexec.engine.events import EngineEvent, Outcome
    from aeroexec.engine.execution.process import (
        BehaviorContext,
        BehaviorLibrary,
        BehaviorProcess,
        EngineSettings,
        Situation,
    )
    from aeroexec.engine.execution.resources import Process, ProcessRegistry
    from aeroexec.engine.robots import RobotKind
    from aeroexec.engine.supervision.changes import MissionChange
