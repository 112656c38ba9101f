"""The aerial behavior library as the library registry asks for it: every behavior class of this package and the
capability processes of its modules.

Every :class:`BehaviorProcess` subclass defined in a module of this package with a ``behavior = "NAME"`` is
registered: adding a behavior is its catalog entry and its class (docs/adding-a-behavior.md). Capability processes
are listed by name in each module's ``*_PROCESSES`` mapping.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import sys

from aeroexec.engine.behaviors.communication import COMMUNICATION_PROCESSES
from aeroexec.engine.behaviors.localization import LOCALIZATION_PROCESSES
from aeroexec.engine.behaviors.perception import PERCEPTION_PROCESSES
from aeroexec.engine.behaviors.planning import PLANNING_PROCESSES
from aeroexec.engine.behaviors.recording import RECORDING_PROCESSES
from aeroexec.engine.behaviors.targets import TARGET_PROCESSES
from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess
from aeroexec.engine.execution.resources import ProcessRegistry

__all__ = ["aerial_behaviors", "aerial_processes"]


def _behavior_classes() -> list[type[BehaviorProcess]]:
    found = []
    package = sys.modules[__package__]  # its search path, which a test or a plugin may extend
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__package__}.{info.name}")
        found += [cls for cls in vars(module).values()
                  if inspect.isclass(cls) and issubclass(cls, BehaviorProcess)
                  and cls.__module__ == module.__name__ and cls.behavior]
    return found


def aerial_behaviors() -> BehaviorLibrary:
    """Every behavior implemented for the aerial catalog."""
    return BehaviorLibrary(_behavior_classes())


def aerial_processes() -> ProcessRegistry:
    """The capability processes; names without an implementation run as idle processes."""
    return ProcessRegistry({**PERCEPTION_PROCESSES, **COMMUNICATION_PROCESSES, **PLANNING_PROCESSES,
                            **LOCALIZATION_PROCESSES, **TARGET_PROCESSES, **RECORDING_PROCESSES})
