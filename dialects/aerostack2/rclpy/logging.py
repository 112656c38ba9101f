"""``rclpy.logging`` as a mission sees it: ``get_logger(name)`` gives a logger whose lines go to aeroexec's log
(Python's ``logging``, under ``rclpy.NAME``), as ROS 2's go to the console and the node's log."""

from __future__ import annotations

import logging
from typing import Any


class RcutilsLogger:
    """What ``rclpy.logging.get_logger`` returns: ``debug``, ``info``, ``warning``/``warn``, ``error``, ``fatal``
    (each with ROS 2's keyword arguments, such as ``once`` and ``throttle_duration_sec``, which are ignored)."""

    def __init__(self, name: str = "") -> None:
        self.name = name
        self._logger = logging.getLogger(f"rclpy.{name}" if name else "rclpy")

    def get_child(self, name: str) -> RcutilsLogger:
        return RcutilsLogger(f"{self.name}.{name}" if self.name else name)

    def set_level(self, level: Any) -> bool:
        return True

    def get_effective_level(self) -> int:
        return self._logger.getEffectiveLevel()

    def debug(self, message: Any, **_: Any) -> bool:
        self._logger.debug("%s", message)
        return True

    def info(self, message: Any, **_: Any) -> bool:
        self._logger.info("%s", message)
        return True

    def warning(self, message: Any, **_: Any) -> bool:
        self._logger.warning("%s", message)
        return True

    warn = warning

    def error(self, message: Any, **_: Any) -> bool:
        self._logger.error("%s", message)
        return True

    def fatal(self, message: Any, **_: Any) -> bool:
        self._logger.critical("%s", message)
        return True


def get_logger(name: str = "") -> RcutilsLogger:
    """The logger ``name`` (ROS 2's ``rclpy.logging.get_logger``)."""
    return RcutilsLogger(name)


__all__ = ["RcutilsLogger", "get_logger"]
