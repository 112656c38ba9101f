"""A package's public names imported when first used (PEP 562's module ``__getattr__``).

``from aeroexec.drones.sim import SimulatedDrone`` still works, but importing the package, or any one module of it,
no longer imports every module behind its names: ``verify`` reads a world without loading the simulated drone. A
package lists its names and the modules they come from::

    __getattr__ = lazy_names(__name__, {"SimulatedDrone": "drone", "World": "world"})
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping

TYPE_CHECKING = False  # typing is not imported at run time: every command would pay for it (~3 ms)
if TYPE_CHECKING:
    from typing import Any

__all__ = ["lazy_logger", "lazy_module", "lazy_names"]


def lazy_names(package: str, names: Mapping[str, str]) -> Callable[[str], Any]:
    """The ``__getattr__`` of ``package``: each name of ``names`` from its module (relative to the package), imported
    the first time the name is asked for and kept in the package from then on."""

    def __getattr__(name: str) -> Any:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{module}"), name)
        setattr(sys.modules[package], name, value)
        return value

    return __getattr__


class _LazyLogger:
    """``logging.getLogger(name)``, with :mod:`logging` imported when something is first logged."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        self.name = name

    def __getattr__(self, method: str) -> Any:
        import logging

        return getattr(logging.getLogger(self.name), method)


def lazy_logger(name: str) -> Any:
    """A module's logger that imports :mod:`logging` only when it logs: for the modules ``aeroexec --help`` reads,
    where importing ``logging`` costs every command ~5 ms."""
    return _LazyLogger(name)


class _LazyModule:
    """A module imported when one of its names is first read; each name read is then kept here."""

    def __init__(self, name: str) -> None:
        self.__dict__["_module_name"] = name

    def __getattr__(self, name: str) -> Any:
        value = getattr(importlib.import_module(self._module_name), name)
        self.__dict__[name] = value
        return value

    def __repr__(self) -> str:
        return f"<module {self._module_name!r}, imported when first used>"


def lazy_module(name: str) -> Any:
    """The module ``name``, imported when one of its names is first read: for a module a reader uses only on the path
    that reads a file (PyYAML, ~15 ms, when a catalog or a world comes parsed from the user's cache folder).
    Its submodules are names of it once it is imported (``yaml.constructor.SafeConstructor``)."""
    return _LazyModule(name)
