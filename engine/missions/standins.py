"""The mission APIs aeroexec stands in for, under the names missions import them by.

Aerostack's missions import ``executive_engine_api`` (Levant) or ``mission_execution_control`` (Sirocco);
Aerostack2's scripts import ``rclpy``, ``as2_python_api`` and ``as2_msgs``. aeroexec serves them from
``aeroexec.aerostack.<name>`` (the folder ``aerostack/``) and installs nothing under those names: an environment
with ROS 2 keeps its own ``rclpy``, and a program that embeds aeroexec imports what it would without it.

A mission aeroexec loads imports through :func:`mission_import`: an import of one of :data:`NAMES` (or of a
module in it) gets aeroexec's module, whatever else the environment holds, since a mission aeroexec flies talks to
its engine, not to a ROS graph. Nothing is put in ``sys.modules`` under those names: only the mission's own code
sees them.
"""

from __future__ import annotations

import builtins
import sys
from collections.abc import Callable
from typing import Any

#: Where aeroexec's mission APIs are installed.
PACKAGE = "aeroexec.aerostack"
#: The top-level names a mission imports them by.
NAMES = frozenset({"rclpy", "as2_python_api", "as2_msgs", "executive_engine_api", "mission_execution_control"})


def stands_in(module: str) -> bool:
    """True when aeroexec serves ``module`` (``rclpy``, ``as2_python_api.drone_interface``...) to its missions."""
    return module.partition(".")[0] in NAMES


def mission_import(real_import: Callable[..., Any] | None = None) -> Callable[..., Any]:
    """``__import__`` as a mission sees it: :data:`NAMES` and their modules are aeroexec's (``PACKAGE.<name>``),
    every other import is ``real_import``'s (``builtins.__import__`` when None)."""
    real_import = real_import or builtins.__import__

    def import_(name: str, globals: Any = None, locals: Any = None, fromlist: Any = (), level: int = 0) -> Any:
        if level or not stands_in(name):
            return real_import(name, globals, locals, fromlist, level)
        try:
            module = real_import(f"{PACKAGE}.{name}", None, None, fromlist, 0)
        except ModuleNotFoundError as missing:  # in the mission's words: No module named 'executive_engine_api.x'
            raise ModuleNotFoundError(str(missing).replace(f"{PACKAGE}.", ""), name=name) from None
        return module if fromlist else sys.modules[f"{PACKAGE}.{name.partition('.')[0]}"]

    return import_


def mission_builtins() -> dict[str, Any]:
    """The builtins of a mission's module: :func:`mission_import` as its ``__import__``."""
    return {**vars(builtins), "__import__": mission_import()}


__all__ = ["NAMES", "PACKAGE", "mission_builtins", "mission_import", "stands_in"]
