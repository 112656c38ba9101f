"""A stand-in for ``rclpy`` in missions written for Aerostack2: what such scripts do with it, on the engine.

``init`` (with the ROS arguments of the script's command line: ``aeroexec run script.py -- --ros-args -p
NAME:=VALUE``), ``ok``, ``shutdown``, ``logging.get_logger``; a script's own node (``rclpy.node.Node``: logger,
name, parameters, clock, timers, publishers of messages used as data; ``rclpy.qos``' profiles and
``rclpy.callback_groups`` as data) and its spinning (``spin``, ``spin_once``, ``spin_until_future_complete``, the
executors of ``rclpy.executors``), whose timer callbacks run on the engine's clock. Any other use raises
:class:`~aeroexec.dialects.ros.RosFeatureError`: this mission uses ROS 2 beyond the drone interface (``aeroexec
verify`` says so before flight, at the line).
"""

from __future__ import annotations

import importlib
import sys
from typing import Any

from aeroexec.dialects import ros
from aeroexec.dialects.aerostack2.rclpy import context as _contexts


def init(*, args: list[str] | None = None, context: Any = None, **_: Any) -> None:
    """Start the (stand-in) ROS 2 context with the ROS arguments of ``args`` (the script's ``sys.argv`` when
    None): the engine is the only node a mission talks to."""
    (context or _contexts.DEFAULT).init(list(sys.argv if args is None else args))
    ros.install()


def ok(*, context: Any = None) -> bool:
    """True between :func:`init` and :func:`shutdown` (a ``while rclpy.ok()`` loop runs until the time limit)."""
    return (context or _contexts.DEFAULT).ok()


def shutdown(*, context: Any = None, **_: Any) -> None:
    """End the context: a spin running ends (a timer's callback may call it). The drone is left as the mission
    left it; the run lands it."""
    (context or _contexts.DEFAULT).shutdown()


def try_shutdown(*, context: Any = None, **_: Any) -> None:
    shutdown(context=context)


def create_node(node_name: str, **kwargs: Any) -> Any:
    """``rclpy.node.Node(node_name, **kwargs)``."""
    return node.Node(node_name, **kwargs)


def get_global_executor() -> Any:
    return executors.get_global_executor()


def spin(node: Any, executor: Any = None) -> None:
    """Run ``node``'s callbacks (its timers') until the context is shut down (``rclpy.shutdown()``)."""
    executor = executor or executors.get_global_executor()
    try:
        executor.add_node(node)
        while executor.context.ok():
            executor.spin_once()
    finally:
        executor.remove_node(node)


def spin_once(node: Any, *, executor: Any = None, timeout_sec: float | None = None) -> None:
    """Run one of ``node``'s callbacks, waiting at most ``timeout_sec`` seconds for one to be due."""
    executor = executor or executors.get_global_executor()
    try:
        executor.add_node(node)
        executor.spin_once(timeout_sec=timeout_sec)
    finally:
        executor.remove_node(node)


def spin_until_future_complete(node: Any, future: Any, executor: Any = None,
                               timeout_sec: float | None = None) -> None:
    """Run ``node``'s callbacks until ``future`` is done (or ``timeout_sec`` has passed)."""
    executor = executor or executors.get_global_executor()
    try:
        executor.add_node(node)
        executor.spin_until_future_complete(future, timeout_sec)
    finally:
        executor.remove_node(node)


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    return ros.Refused(f"rclpy.{name}")


# rclpy's modules, as ROS 2 has them (imported by name: this module's __getattr__ would answer a from-import)
logging = importlib.import_module(f"{__name__}.logging")
node = importlib.import_module(f"{__name__}.node")
executors = importlib.import_module(f"{__name__}.executors")
parameter = importlib.import_module(f"{__name__}.parameter")
time = importlib.import_module(f"{__name__}.time")
duration = importlib.import_module(f"{__name__}.duration")
clock = importlib.import_module(f"{__name__}.clock")
timer = importlib.import_module(f"{__name__}.timer")
task = importlib.import_module(f"{__name__}.task")
exceptions = importlib.import_module(f"{__name__}.exceptions")
publisher = importlib.import_module(f"{__name__}.publisher")
utilities = importlib.import_module(f"{__name__}.utilities")
qos = importlib.import_module(f"{__name__}.qos")
callback_groups = importlib.import_module(f"{__name__}.callback_groups")

__all__ = ["callback_groups", "clock", "create_node", "duration", "exceptions", "executors", "get_global_executor",
           "init", "logging", "node", "ok", "parameter", "publisher", "qos", "shutdown", "spin", "spin_once",
           "spin_until_future_complete", "task", "time", "timer", "try_shutdown", "utilities"]
