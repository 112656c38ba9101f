"""Old import paths of modules that moved when ``engine/`` was split by the paper's parts (0.2), and when the
run's files moved to the flight package (0.3).

``import aeroexec.engine.specialist`` still works for one release: it gives a
module that forwards every name to the new place, with a DeprecationWarning
naming it. Nothing here imports the new modules until an old name is used.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import sys
import types
import warnings

TYPE_CHECKING = False  # typing is not imported at run time: every command would pay for it (~3 ms)
if TYPE_CHECKING:
    from typing import Any

MOVED = {
    "aeroexec.engine.specialist": "aeroexec.engine.catalog.specialist",
    "aeroexec.engine.catalog_loader": "aeroexec.engine.catalog.loader",
    "aeroexec.engine.descriptors": "aeroexec.engine.catalog.descriptors",
    "aeroexec.engine.arguments": "aeroexec.engine.catalog.arguments",
    "aeroexec.engine.coordinator": "aeroexec.engine.execution.coordinator",
    "aeroexec.engine.process": "aeroexec.engine.execution.process",
    "aeroexec.engine.resources": "aeroexec.engine.execution.resources",
    "aeroexec.engine.activation": "aeroexec.engine.execution.activation",
    "aeroexec.engine.explain": "aeroexec.engine.execution.explain",
    "aeroexec.engine.updaters": "aeroexec.engine.execution.updaters",
    "aeroexec.engine.exploration": "aeroexec.engine.planning.exploration",
    "aeroexec.engine.mapping": "aeroexec.engine.planning.mapping",
    "aeroexec.engine.mission_bridge": "aeroexec.engine.missions.bridge",
    "aeroexec.engine.mission_check": "aeroexec.engine.missions.check",
    "aeroexec.engine.mission_sequence": "aeroexec.engine.missions.sequence",
    "aeroexec.engine.control": "aeroexec.flight.control",
    "aeroexec.engine.operator": "aeroexec.engine.supervision.operator",
    "aeroexec.engine.messages": "aeroexec.engine.supervision.messages",
    "aeroexec.engine.flight_log": "aeroexec.flight.flight_log",
    "aeroexec.engine.flight_summary": "aeroexec.flight.summary",
    "aeroexec.engine.supervision.control": "aeroexec.flight.control",
    "aeroexec.engine.supervision.flight_log": "aeroexec.flight.flight_log",
    "aeroexec.engine.supervision.flight_summary": "aeroexec.flight.summary",
    "aeroexec.engine.supervision.flight_end": "aeroexec.flight.ending",
    "aeroexec.engine.supervision.run_status": "aeroexec.flight.run_status",
    "aeroexec.engine.output": "aeroexec.engine.supervision.output",
    "aeroexec.drones.sim.mavlink_vehicle": "aeroexec.drones.sim.mavlink.vehicle",
}


class _Forward:  # an importlib.abc.Loader by its methods: importlib.abc costs every command ~5 ms to import
    def __init__(self, new: str) -> None:
        self.new = new

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        warnings.warn(f"{spec.name} moved to {self.new}; the old path goes away in the next release",
                      DeprecationWarning, stacklevel=2)
        target = importlib.import_module(self.new)
        module = types.ModuleType(spec.name, target.__doc__)

        def forward(name: str) -> Any:
            return getattr(target, name)

        module.__getattr__ = forward  # type: ignore[method-assign]
        module.__all__ = getattr(target, "__all__", [n for n in vars(target) if not n.startswith("_")])
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        """Nothing to run: every name is read from the new module."""


class _MovedFinder:  # an importlib.abc.MetaPathFinder by its method
    def find_spec(self, name: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        new = MOVED.get(name)
        return importlib.machinery.ModuleSpec(name, _Forward(new)) if new else None


def install() -> None:
    """Put the finder of old paths at the end of ``sys.meta_path`` (real modules always win)."""
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.append(_MovedFinder())
