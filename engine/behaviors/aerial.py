"""The aerial behavior library as the library registry asks for it: every behavior class of this package and the
capability processes of its modules.

Every :class:`BehaviorProcess` subclass defined in a module of this package with a ``behavior = "NAME"`` is
registered: adding a behavior is its catalog entry and its class (docs/adding-a-behavior.md). Capability processes
are listed by name in each module's ``*_PROCESSES`` mapping.
"""

from __future__ import annotations

import importlib
import inspect
import sys

from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess
from aeroexec.engine.execution.resources import ProcessRegistry

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

__all__ = ["PROCESS_MODULES", "aerial_behaviors", "aerial_module_index", "aerial_processes", "processes_of_module"]

#: The modules listing capability processes, and the mapping of each that lists them, in the order they are merged
#: (a later module's name wins).
PROCESS_MODULES = {"perception": "PERCEPTION_PROCESSES", "communication": "COMMUNICATION_PROCESSES",
                   "planning": "PLANNING_PROCESSES", "localization": "LOCALIZATION_PROCESSES",
                   "targets": "TARGET_PROCESSES", "recording": "RECORDING_PROCESSES"}


def _behavior_classes() -> list[type[BehaviorProcess]]:
    import pkgutil  # here: a run whose library's index is kept makes processes without listing the package

    found = []
    package = sys.modules[__package__]  # its search path, which a test or a plugin may extend
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__package__}.{info.name}")
        found += [cls for cls in vars(module).values()
                  if inspect.isclass(cls) and issubclass(cls, BehaviorProcess)
                  and cls.__module__ == module.__name__ and cls.behavior]
    return found


def processes_of_module(module: str) -> dict[str, Any]:
    """The capability processes the module ``module`` (of :data:`PROCESS_MODULES`) lists, by name."""
    return dict(getattr(importlib.import_module(f"{__package__}.{module}"), PROCESS_MODULES[module]))


def aerial_behaviors() -> BehaviorLibrary:
    """Every behavior implemented for the aerial catalog."""
    return BehaviorLibrary(_behavior_classes())


def aerial_processes() -> ProcessRegistry:
    """The capability processes; names without an implementation run as idle processes."""
    registry = ProcessRegistry()
    for module in PROCESS_MODULES:
        for name, factory in processes_of_module(module).items():
            registry.register(name, factory)
    return registry


def aerial_module_index() -> tuple[dict[str, str], dict[str, str]]:
    """The module implementing each behavior, and the module of :data:`PROCESS_MODULES` listing each capability
    process, read by importing them all (``aeroexec.engine.library`` keeps them, so a run imports only the modules
    it uses)."""
    behaviors = {cls.behavior: cls.__module__ for cls in _behavior_classes()}
    processes: dict[str, str] = {}
    for module in PROCESS_MODULES:
        processes.update(dict.fromkeys(processes_of_module(module), module))
    return behaviors, processes
