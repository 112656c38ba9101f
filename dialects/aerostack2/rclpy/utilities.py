"""``rclpy.utilities`` as a mission sees it: ``remove_ros_args`` (a command line without its ROS arguments, for
the script's own argparse), ``ok``, ``get_default_context``."""

from __future__ import annotations

import sys
from typing import Any

from aeroexec.dialects.aerostack2.rclpy import context as contexts


def remove_ros_args(args: list[str] | None = None) -> list[str]:
    """``args`` (``sys.argv`` when None) without what ``--ros-args`` begins, up to a lone ``--`` or the end."""
    kept, ros = [], False
    for word in sys.argv if args is None else args:
        if word == "--ros-args":
            ros = True
        elif ros and word == "--":
            ros = False
        elif not ros:
            kept.append(word)
    return kept


def ok(*, context: Any = None) -> bool:
    return (context or contexts.DEFAULT).ok()


def get_default_context() -> contexts.Context:
    return contexts.DEFAULT


__all__ = ["get_default_context", "ok", "remove_ros_args"]
