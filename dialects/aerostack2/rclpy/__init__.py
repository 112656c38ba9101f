"""A stand-in for ``rclpy`` in missions written for Aerostack2: what such scripts do with it (``init``, ``ok``,
``shutdown``, ``logging.get_logger``) and nothing else. Any other use raises
:class:`~aeroexec.dialects.ros.RosFeatureError`: this mission uses ROS 2 beyond the drone interface
(``aeroexec verify`` says so before flight, at the line).
"""

from __future__ import annotations

import importlib
from typing import Any

from aeroexec.dialects import ros

_running = False


def init(*args: Any, **kwargs: Any) -> None:
    """Start the (stand-in) ROS 2 context: the engine is the only node a mission talks to."""
    global _running
    _running = True
    ros.install()


def ok(*args: Any, **kwargs: Any) -> bool:
    """True between :func:`init` and :func:`shutdown` (a ``while rclpy.ok()`` loop runs until the time limit)."""
    return _running


def shutdown(*args: Any, **kwargs: Any) -> None:
    """End the context (again: nothing happens). The drone is left as the mission left it; the run lands it."""
    global _running
    _running = False


def try_shutdown(*args: Any, **kwargs: Any) -> None:
    shutdown()


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    return ros.Refused(f"rclpy.{name}")


# rclpy.logging, as ROS 2 has it (imported by name: this module's __getattr__ would answer a from-import)
logging = importlib.import_module(f"{__name__}.logging")

__all__ = ["init", "logging", "ok", "shutdown", "try_shutdown"]
