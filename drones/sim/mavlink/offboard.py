"""Offboard control of the simulated vehicle: SET_POSITION_TARGET_* setpoints, engagement and loss failsafe.

As on PX4, OFFBOARD can only be entered while setpoints stream in, and when they stop for longer than
COM_OF_LOSS_T seconds of wall time (the client's clock, whatever the simulation speed) the vehicle holds.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

from aeroexec.drones.angles import wrap180 as _wrap180
from aeroexec.drones.interface import CommandHandle, Failure, Telemetry
from aeroexec.drones.sim.mavlink.telemetry import heading_to_yaw
from pymavlink.dialects.v20 import common as mavlink

logger = logging.getLogger(__name__)

_IGNORE_POSITION = 0b111
_IGNORE_VELOCITY = 0b111 << 3
_IGNORE_YAW = 1 << 10
_IGNORE_YAW_RATE = 1 << 11
_YAW_GAIN = 2.0  # 1/s: yaw rate per degree of heading error when the setpoint holds an absolute yaw
_MAX_YAW_RATE = 90.0  # deg/s


@dataclass(frozen=True, slots=True)
class Setpoint:
    """One offboard setpoint in ENU: a position or a velocity, with an absolute yaw or a yaw rate."""

    position: tuple[float, float, float] | None = None
    velocity: tuple[float, float, float] | None = None
    yaw: float | None = None  # degrees, ENU
    yaw_rate: float | None = None  # deg/s, counterclockwise


def _body_to_enu(forward: float, right: float, down: float, yaw_deg: float) -> tuple[float, float, float]:
    yaw = math.radians(yaw_deg)
    return (
        forward * math.cos(yaw) + right * math.sin(yaw),
        forward * math.sin(yaw) - right * math.cos(yaw),
        -down,
    )


def setpoint_from_local_ned(msg, tel: Telemetry) -> Setpoint | None:
    """A SET_POSITION_TARGET_LOCAL_NED as an ENU setpoint; None when the frame or mask is not supported."""
    mask = msg.type_mask
    frame = msg.coordinate_frame
    body = frame in (mavlink.MAV_FRAME_BODY_NED, mavlink.MAV_FRAME_BODY_OFFSET_NED, mavlink.MAV_FRAME_BODY_FRD)
    offset = frame in (mavlink.MAV_FRAME_LOCAL_OFFSET_NED, mavlink.MAV_FRAME_BODY_OFFSET_NED)
    if not body and frame not in (mavlink.MAV_FRAME_LOCAL_NED, mavlink.MAV_FRAME_LOCAL_OFFSET_NED):
        return None
    position = velocity = None
    if mask & _IGNORE_POSITION != _IGNORE_POSITION:
        if body:
            dx, dy, dz = _body_to_enu(msg.x, msg.y, msg.z, tel.yaw)
        else:
            dx, dy, dz = msg.y, msg.x, -msg.z
        if body or offset:
            px, py, pz = tel.position
            position = (px + dx, py + dy, pz + dz)
        else:
            position = (dx, dy, dz)
    elif mask & _IGNORE_VELOCITY != _IGNORE_VELOCITY:
        velocity = _body_to_enu(msg.vx, msg.vy, msg.vz, tel.yaw) if body else (msg.vy, msg.vx, -msg.vz)
    else:
        return None
    yaw = yaw_rate = None
    if not mask & _IGNORE_YAW and math.isfinite(msg.yaw):
        yaw = heading_to_yaw(math.degrees(msg.yaw))
    elif not mask & _IGNORE_YAW_RATE and math.isfinite(msg.yaw_rate):
        yaw_rate = -math.degrees(msg.yaw_rate)
    return Setpoint(position, velocity, yaw, yaw_rate)


def setpoint_from_global_int(msg, tel: Telemetry, world) -> Setpoint | None:
    """A SET_POSITION_TARGET_GLOBAL_INT (position only) as an ENU setpoint."""
    if msg.type_mask & _IGNORE_POSITION == _IGNORE_POSITION:
        return None
    lat, lon = msg.lat_int * 1e-7, msg.lon_int * 1e-7
    if msg.coordinate_frame in (mavlink.MAV_FRAME_GLOBAL_INT, mavlink.MAV_FRAME_GLOBAL):
        alt = msg.alt
    else:  # relative to home
        alt = msg.alt + (tel.home[2] if tel.home else world.to_geodetic((0.0, 0.0, 0.0))[2])
    yaw = None
    if not msg.type_mask & _IGNORE_YAW and math.isfinite(msg.yaw):
        yaw = heading_to_yaw(math.degrees(msg.yaw))
    return Setpoint(position=tuple(world.to_enu(lat, lon, alt)), yaw=yaw)


class OffboardControl:
    """Keeps the latest setpoint and its wall-clock age; drives the simulated drone while it is in OFFBOARD."""

    def __init__(self) -> None:
        self.setpoint: Setpoint | None = None
        self.received_at = -math.inf  # wall time of the last setpoint
        self._applied: Setpoint | None = None
        self._applied_rate: float | None = None

    def receive(self, setpoint: Setpoint, wall_now: float) -> None:
        self.setpoint = setpoint
        self.received_at = wall_now

    def fresh(self, wall_now: float, loss_timeout: float) -> bool:
        return wall_now - self.received_at <= max(loss_timeout, 0.5)

    def engage(self, drone, tel: Telemetry, wall_now: float, loss_timeout: float) -> CommandHandle:
        """Switch the simulated drone to OFFBOARD, if setpoints are streaming, and apply the latest one."""
        if self.setpoint is None or not self.fresh(wall_now, loss_timeout):
            return CommandHandle.failed(
                "set_mode", Failure.DENIED, "offboard denied: no setpoints streaming (send them before switching)"
            )
        handle = drone.set_mode("OFFBOARD")
        if handle.done and handle.ok:
            self._applied = None
            self._apply(drone, tel)
        return handle

    def step(self, drone, tel: Telemetry, wall_now: float, loss_timeout: float) -> str | None:
        """Apply new setpoints while in OFFBOARD; returns a failsafe reason when the stream was lost."""
        if tel.flight_mode != "OFFBOARD":
            self._applied = None
            return None
        if not self.fresh(wall_now, loss_timeout):
            self._applied = None
            return f"offboard setpoints lost for more than {loss_timeout:g} s"
        self._apply(drone, tel)
        return None

    def _apply(self, drone, tel: Telemetry) -> None:
        sp = self.setpoint
        if sp is None:
            return
        if sp.position is not None:
            if sp != self._applied:
                self._report(drone.offboard_position(sp.position, sp.yaw))
            self._applied = sp
            return
        rate = sp.yaw_rate if sp.yaw_rate is not None else 0.0
        if sp.yaw is not None:
            rate = max(-_MAX_YAW_RATE, min(_MAX_YAW_RATE, _YAW_GAIN * _wrap180(sp.yaw - tel.yaw)))
            if abs(rate) < 0.5:
                rate = 0.0
        if sp != self._applied or rate != self._applied_rate:
            self._report(drone.set_velocity(sp.velocity, rate))
        self._applied = sp
        self._applied_rate = rate

    @staticmethod
    def _report(handle: CommandHandle) -> None:
        if handle.done and not handle.ok:
            logger.info("offboard setpoint refused by the simulation: %s", handle.reason)
