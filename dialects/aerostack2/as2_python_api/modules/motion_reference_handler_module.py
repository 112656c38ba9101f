"""Aerostack2's ``motion_ref_handler`` module (DroneInterfaceTeleop): motion references as behaviors that
return at once: hover is KEEP_HOVERING, a position reference GO_TO_POINT, a speed reference KEEP_MOVING along
the heading's axes (or up, or down), a zero speed KEEP_HOVERING."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase
from aeroexec.dialects.aerostack2.behaviors import EARTH_FRAMES, Request, degrees
from aeroexec.dialects.ros import ROS2_BEYOND
from aeroexec.engine.errors import WRONG_VALUE

if TYPE_CHECKING:
    from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase

#: Degrees a speed reference may be off an axis of the heading and still fly along it.
AXIS_TOLERANCE = 2.0
_HEADINGS = {0: "FORWARD", 90: "LEFT", 180: "BACKWARD", 270: "RIGHT"}


class _Motion:
    def __init__(self, module: MotionReferenceHandlerModule) -> None:
        self._module = module

    def _list(self, value: Any, what: str) -> list[float] | None:
        if isinstance(value, list | tuple) and len(value) == 3 and all(isinstance(v, int | float) for v in value):
            return [float(v) for v in value]
        self._module._drone.refuse("motion_ref_handler", WRONG_VALUE,
                                   f"The {what} {value!r} is not correct ([x, y, z] is expected; ROS messages "
                                   f"are not available: {ROS2_BEYOND})")
        return None

    def _frame(self, *frames: str) -> bool:
        bad = [f for f in frames if isinstance(f, str) and f.strip() not in EARTH_FRAMES]
        if bad:
            self._module._drone.refuse("motion_ref_handler", WRONG_VALUE,
                                       f"The frame {bad[0]!r} is not correct: references are in the earth frame "
                                       f"({ROS2_BEYOND})")
        return not bad


class _Position(_Motion):
    def send_position_command_with_yaw_angle(self, pose: Any, twist_limit: Any = None, pose_frame_id: str = "",
                                             twist_frame_id: str = "", yaw_angle: float | None = None) -> bool:
        point = self._list(pose, "position")
        if point is None or not self._frame(pose_frame_id, twist_frame_id):
            return False
        arguments: dict[str, Any] = {"COORDINATES": tuple(point)}
        if isinstance(twist_limit, int | float) and twist_limit > 0:
            arguments["SPEED"] = float(twist_limit)
        if isinstance(yaw_angle, int | float):
            arguments["YAW_ANGLE_AT_THE_END"] = degrees(yaw_angle)
        return self._module._reference(Request("GO_TO_POINT", arguments, wait=False))

    def send_position_command_with_yaw_speed(self, pose: Any, twist_limit: Any = None, pose_frame_id: str = "",
                                             twist_frame_id: str = "", yaw_speed: float | None = None) -> bool:
        return self.send_position_command_with_yaw_angle(pose, twist_limit, pose_frame_id, twist_frame_id)


class _Speed(_Motion):
    def send_speed_command_with_yaw_speed(self, twist: Any, twist_frame_id: str = "",
                                          yaw_speed: float | None = None) -> bool:
        velocity = self._list(twist, "speed")
        if velocity is None or not self._frame(twist_frame_id):
            return False
        return self._module._reference(self._module._moving(velocity))

    def send_speed_command_with_yaw_angle(self, twist: Any, pose: Any = None, twist_frame_id: str = "",
                                          yaw_angle: float | None = None) -> bool:
        return self.send_speed_command_with_yaw_speed(twist, twist_frame_id)


class _SpeedInAPlane(_Motion):
    def send_speed_in_a_plane_command_with_yaw_speed(self, twist: Any, height: Any, pose_frame_id: str = "",
                                                     twist_frame_id: str = "", yaw_speed: float | None = None) -> bool:
        velocity = self._list(twist, "speed")
        if velocity is None or not self._frame(pose_frame_id, twist_frame_id):
            return False
        return self._module._reference(self._module._moving([velocity[0], velocity[1], 0.0]))

    def send_speed_in_a_plane_command_with_yaw_angle(self, twist: Any, height: Any, pose_frame_id: str = "",
                                                     twist_frame_id: str = "", yaw_angle: Any = None) -> bool:
        return self.send_speed_in_a_plane_command_with_yaw_speed(twist, height, pose_frame_id, twist_frame_id)


class MotionReferenceHandlerModule(ModuleBase):
    """motion_ref_handler module: ``hover()``, ``position``, ``speed`` and ``speed_in_a_plane`` references."""

    __alias__ = "motion_ref_handler"

    def __init__(self, drone: DroneInterfaceBase) -> None:
        super().__init__(drone, self.__alias__)
        self.position = _Position(self)
        self.speed = _Speed(self)
        self.speed_in_a_plane = _SpeedInAPlane(self)

    def __call__(self, *args: Any, **kwargs: Any) -> None:
        return None

    def hover(self) -> None:
        """Stop and hover where the drone is."""
        self._reference(Request("KEEP_HOVERING", {}, wait=False))

    def _reference(self, request: Request) -> bool:
        return self._perform([request])

    def _moving(self, velocity: list[float]) -> Request:
        """KEEP_MOVING along ``velocity`` (earth frame) when it lies along an axis of the heading or the vertical;
        KEEP_HOVERING for no speed."""
        speed = math.dist(velocity, (0.0, 0.0, 0.0))
        if speed == 0.0:
            return Request("KEEP_HOVERING", {}, wait=False)
        if math.hypot(velocity[0], velocity[1]) < 1e-9:
            return Request("KEEP_MOVING", {"DIRECTION": "UPWARD" if velocity[2] > 0 else "DOWNWARD", "SPEED": speed},
                           wait=False)
        heading = (math.degrees(math.atan2(velocity[1], velocity[0])) - self._drone.telemetry().yaw) % 360.0
        for angle, direction in _HEADINGS.items():
            if abs((heading - angle + 180.0) % 360.0 - 180.0) <= AXIS_TOLERANCE and abs(velocity[2]) < 1e-9:
                return Request("KEEP_MOVING", {"DIRECTION": direction, "SPEED": speed}, wait=False)
        return Request("KEEP_MOVING", {"DIRECTION": f"{heading:.0f} degrees from the heading", "SPEED": speed},
                       wait=False)
