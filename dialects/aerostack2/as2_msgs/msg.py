"""The constants of Aerostack2's messages that missions use (``as2_msgs/msg/*.msg``); any other message is a
stand-in whose use is refused (this mission uses ROS 2 beyond the drone interface)."""

from __future__ import annotations

from typing import Any

from aeroexec.dialects import ros, ros_messages
from aeroexec.dialects.aerostack2 import behaviors as aerostack2


class YawMode:
    """as2_msgs/msg/YawMode.msg"""

    KEEP_YAW = aerostack2.KEEP_YAW
    PATH_FACING = aerostack2.PATH_FACING
    FIXED_YAW = aerostack2.FIXED_YAW
    YAW_FROM_TOPIC = 3
    YAW_FROM_ORIENTATION = 4
    YAW_TO_FRAME = 5
    FACE_REFERENCE = 6

    def __init__(self, mode: int = 0, angle: float = 0.0) -> None:
        self.mode, self.angle = mode, angle


class BehaviorStatus:
    """as2_msgs/msg/BehaviorStatus.msg"""

    IDLE = 0
    RUNNING = 1
    PAUSED = 2

    def __init__(self, status: int = 0) -> None:
        self.status = status


class PlatformStatus:
    """as2_msgs/msg/PlatformStatus.msg"""

    EMERGENCY = -1
    DISARMED = 0
    LANDED = 1
    TAKING_OFF = 2
    FLYING = 3
    LANDING = 4

    def __init__(self, state: int = 0) -> None:
        self.state = state


class AlertEvent:
    """as2_msgs/msg/AlertEvent.msg"""

    KILL_SWITCH = -1
    EMERGENCY_HOVER = -2
    EMERGENCY_LAND = -3
    INFO_ALERT = 0
    FORCE_HOVER = 1
    FORCE_LAND = 2

    def __init__(self, alert: int = 0, description: str = "") -> None:
        self.alert, self.description = alert, description


PoseWithID = ros_messages.PoseWithID  # as2_msgs/msg/PoseWithID.msg: a path's point (an id and a pose), as data
PoseWithIDArray = ros_messages.PoseWithIDArray
TrajectoryWaypoints = ros_messages.TrajectoryWaypoints  # a path and its yaw mode, with its constants, as data


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    return ros.Refused(f"as2_msgs.msg.{name}")
