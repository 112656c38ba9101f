"""COMMAND_LONG / COMMAND_INT handling of the simulated vehicle: each command's COMMAND_ACK says what the
simulated drone decided (accepted, denied with a STATUSTEXT reason, unsupported, or in progress then final).

Semantics follow PX4: NAV_TAKEOFF's altitude is AMSL (NaN: MIS_TAKEOFF_ALT above home), DO_REPOSITION's
yaw is a heading in radians (as PX4 reads it and MAVSDK sends it), DO_SET_MODE takes PX4 custom modes.
As ArduCopter (the vehicle's ``copter`` is set): DO_SET_MODE takes Copter mode numbers, arming follows the
EKF's pre-arm checks, NAV_TAKEOFF (altitude above home) only in GUIDED, refusals are MAV_RESULT_FAILED.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from aeroexec.drones.interface import CommandHandle, Failure, LandedState
from aeroexec.drones.sim.mavlink.ardupilot import COPTER_MODE_NAMES
from aeroexec.drones.sim.mavlink.telemetry import heading_to_yaw, mode_from_px4
from pymavlink.dialects.v20 import common as mavlink

if TYPE_CHECKING:
    from aeroexec.drones.interface import Telemetry
    from aeroexec.drones.sim.drone import SimulatedDrone
    from aeroexec.drones.sim.mavlink.ardupilot import ArduCopter
    from aeroexec.drones.sim.mavlink.mission import MissionManager
    from aeroexec.drones.sim.mavlink.offboard import OffboardControl
    from aeroexec.drones.sim.mavlink.params import ParameterServer
    from aeroexec.drones.sim.mavlink.telemetry import TelemetryEncoder

logger = logging.getLogger(__name__)


class Vehicle(Protocol):
    """What the command handler uses of the simulated vehicle (:class:`~.vehicle.MavlinkVehicle` serves it)."""

    drone: SimulatedDrone
    latest: Telemetry
    mav: mavlink.MAVLink
    encoder: TelemetryEncoder
    params: ParameterServer
    streams: Any
    offboard: OffboardControl
    mission: MissionManager
    speed_override: float | None
    copter: ArduCopter | None
    last_goto: tuple[tuple[float, float, float], float | None] | None

    def wall_now(self) -> float: ...
    def home(self) -> tuple[float, float, float]: ...
    def cruise_speed(self) -> float: ...
    def statustext(self, severity: int, text: str) -> None: ...
    def send_message(self, msg_id: int) -> None: ...

_FAILURE_TO_RESULT = {
    Failure.DENIED: mavlink.MAV_RESULT_DENIED,
    Failure.UNSUPPORTED: mavlink.MAV_RESULT_UNSUPPORTED,
    Failure.TIMEOUT: mavlink.MAV_RESULT_FAILED,
    Failure.LINK_LOST: mavlink.MAV_RESULT_FAILED,
    Failure.CANCELLED: mavlink.MAV_RESULT_FAILED,
}
_FORCE_MAGIC = 21196
_SIM_MODES = ("HOLD", "TAKEOFF", "LAND", "RETURN")


@dataclass(frozen=True, slots=True)
class Command:
    """A COMMAND_LONG or COMMAND_INT, with x/y as degrees for global frames (param5/6 of a COMMAND_LONG)."""

    command: int
    params: tuple[float, float, float, float]
    x: float
    y: float
    z: float
    frame: int
    source: tuple[int, int]
    long: bool = False  # a COMMAND_LONG (x, y, z from param5..7, no frame)

    @classmethod
    def from_message(cls, msg) -> Command:
        source = (msg.get_srcSystem(), msg.get_srcComponent())
        p = (msg.param1, msg.param2, msg.param3, msg.param4)
        if msg.get_type() == "COMMAND_INT":
            global_frame = msg.frame not in (mavlink.MAV_FRAME_LOCAL_NED, mavlink.MAV_FRAME_MISSION)
            scale = 1e-7 if global_frame else 1.0
            x = msg.x * scale if msg.x != 0 or not global_frame else math.nan
            y = msg.y * scale if msg.y != 0 or not global_frame else math.nan
            return cls(msg.command, p, x, y, msg.z, msg.frame, source)
        return cls(msg.command, p, msg.param5, msg.param6, msg.param7, mavlink.MAV_FRAME_GLOBAL, source, True)


class CommandHandler:
    """Executes commands on the vehicle's simulated drone and acknowledges them."""

    def __init__(self, vehicle: Vehicle) -> None:
        self._v = vehicle
        self._pending: list[tuple[CommandHandle, int, tuple[int, int]]] = []
        self._table = {
            mavlink.MAV_CMD_COMPONENT_ARM_DISARM: self._arm_disarm,
            mavlink.MAV_CMD_NAV_TAKEOFF: self._takeoff,
            mavlink.MAV_CMD_NAV_LAND: lambda c: self._flight(self._v.drone.land),
            mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH: lambda c: self._flight(self._v.drone.return_to_launch),
            mavlink.MAV_CMD_DO_SET_MODE: self._set_mode,
            mavlink.MAV_CMD_DO_REPOSITION: self._reposition,
            mavlink.MAV_CMD_DO_CHANGE_SPEED: self._change_speed,
            mavlink.MAV_CMD_MISSION_START: self._mission_start,
            mavlink.MAV_CMD_DO_SET_MISSION_CURRENT: self._mission_current,
            mavlink.MAV_CMD_SET_MESSAGE_INTERVAL: self._set_interval,
            mavlink.MAV_CMD_GET_MESSAGE_INTERVAL: self._get_interval,
            mavlink.MAV_CMD_REQUEST_MESSAGE: self._request_message,
            mavlink.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: self._autopilot_capabilities,
            mavlink.MAV_CMD_GET_HOME_POSITION: lambda c: self._send_after(mavlink.MAVLINK_MSG_ID_HOME_POSITION),
        }

    def handle(self, msg) -> None:
        cmd = Command.from_message(msg)
        action = self._table.get(cmd.command)
        if action is None:
            logger.debug("command %d unsupported", cmd.command)
            self._ack(cmd.command, mavlink.MAV_RESULT_UNSUPPORTED, cmd.source)
            return
        try:
            outcome = action(cmd)
        except Exception:  # a bug here must not kill the vehicle thread: answer FAILED and log it
            logger.exception("command %d failed in the simulated vehicle", cmd.command)
            self._ack(cmd.command, mavlink.MAV_RESULT_FAILED, cmd.source)
            return
        if callable(outcome):  # accepted, with a message to send after the ack
            self._ack(cmd.command, mavlink.MAV_RESULT_ACCEPTED, cmd.source)
            outcome()
        elif isinstance(outcome, CommandHandle):
            self._finish(outcome, cmd.command, cmd.source)
        else:
            self._ack(cmd.command, outcome, cmd.source)

    def poll(self) -> None:
        """Send the final ack of commands the simulation completes later."""
        still = []
        for handle, command, source in self._pending:
            if handle.done:
                self._finish(handle, command, source)
            else:
                still.append((handle, command, source))
        self._pending = still

    def _finish(self, handle: CommandHandle, command: int, source: tuple[int, int]) -> None:
        if not handle.done:
            self._ack(command, mavlink.MAV_RESULT_IN_PROGRESS, source)
            self._pending.append((handle, command, source))
            return
        if handle.ok:
            self._ack(command, mavlink.MAV_RESULT_ACCEPTED, source)
            return
        self._v.statustext(mavlink.MAV_SEVERITY_CRITICAL, _sentence(handle.reason or handle.failure.value))
        result = _FAILURE_TO_RESULT.get(handle.failure, mavlink.MAV_RESULT_FAILED)
        if self._v.copter is not None and result == mavlink.MAV_RESULT_DENIED:
            result = mavlink.MAV_RESULT_FAILED  # ArduPilot answers a refused arm, takeoff or mode FAILED
        self._ack(command, result, source)

    def _fail(self, text: str) -> int:
        """ArduPilot's refusal: a STATUSTEXT saying why, then MAV_RESULT_FAILED."""
        self._v.statustext(mavlink.MAV_SEVERITY_CRITICAL, text)
        return mavlink.MAV_RESULT_FAILED

    def _flying(self) -> bool:
        tel = self._v.drone.telemetry()
        return tel.armed and tel.landed_state not in (LandedState.ON_GROUND, LandedState.UNKNOWN)

    def _ack(self, command: int, result: int, source: tuple[int, int]) -> None:
        self._v.mav.command_ack_send(command, result, 0, 0, source[0], source[1])

    def _send_after(self, msg_id: int):
        return lambda: self._v.send_message(msg_id)

    # --- flight ------------------------------------------------------------------------------------
    def _flight(self, call, *args) -> CommandHandle:
        """A command that takes the vehicle out of a running mission."""
        self._v.mission.abort("another command")
        return call(*args)

    def _arm_disarm(self, cmd: Command) -> CommandHandle | int:
        if cmd.params[0] >= 0.5:
            copter = self._v.copter
            if copter is not None and not self._v.drone.telemetry().armed:
                refusal = copter.arm_refusal(self._v.latest.time)
                if refusal is not None:
                    return self._fail(refusal)
            return self._v.drone.arm()
        if cmd.params[1] == _FORCE_MAGIC:
            logger.info("forced disarm requested: the simulation decides whether it can disarm now")
        self._v.mission.abort("disarm")
        return self._v.drone.disarm()

    def _takeoff(self, cmd: Command) -> CommandHandle | int:
        if self._v.copter is not None:
            return self._copter_takeoff(cmd)
        home_alt = self._v.home()[2]
        if math.isfinite(cmd.z):
            altitude = (
                cmd.z - home_alt if cmd.frame in (mavlink.MAV_FRAME_GLOBAL, mavlink.MAV_FRAME_GLOBAL_INT) else cmd.z
            )
        else:
            altitude = self._v.params.get("MIS_TAKEOFF_ALT")
        if altitude <= 0.0:
            return CommandHandle.failed(
                "takeoff", Failure.DENIED, f"takeoff denied: altitude {altitude:.1f} m is not above home"
            )
        return self._flight(self._v.drone.takeoff, altitude)

    def _copter_takeoff(self, cmd: Command) -> CommandHandle | int:
        """ArduCopter's user takeoff: GUIDED, armed, landed, to an altitude above home."""
        copter, tel = self._v.copter, self._v.drone.telemetry()  # fresh: an arm may be in the same batch
        relative = cmd.long or cmd.frame in (mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT,
                                             mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
        if not relative:
            return mavlink.MAV_RESULT_DENIED  # COMMAND_INT with another frame
        if not tel.armed:
            return self._fail("Takeoff: motors not armed")
        if copter.mode != "GUIDED":
            return self._fail(f"Takeoff: {copter.mode} has no user takeoff (switch to GUIDED)")
        if tel.landed_state != LandedState.ON_GROUND:
            return self._fail("Takeoff: already flying")
        if not (math.isfinite(cmd.z) and cmd.z > 0.0):
            return self._fail(f"Takeoff: altitude {cmd.z:g} m is not above home")
        return self._flight(self._v.drone.takeoff, cmd.z)

    def _set_mode(self, cmd: Command) -> CommandHandle | int:
        base, main, sub = int(cmd.params[0]), int(cmd.params[1]), int(cmd.params[2])
        if not base & mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            return CommandHandle.failed("set_mode", Failure.UNSUPPORTED, "mode change denied: only custom modes")
        if self._v.copter is not None:
            return self._copter_mode(COPTER_MODE_NAMES.get(main))
        mode = mode_from_px4(main, sub)
        if mode == "MISSION":
            return self._v.mission.start()
        if mode == "OFFBOARD":
            self._v.mission.abort("offboard")
            return self._v.offboard.engage(
                self._v.drone, self._v.latest, self._v.wall_now(), self._v.params.get("COM_OF_LOSS_T")
            )
        if mode in _SIM_MODES:
            return self._flight(self._v.drone.set_mode, mode)
        name = mode or f"custom mode {main}/{sub}"
        return CommandHandle.failed(
            "set_mode", Failure.DENIED, f"{name} denied: not available in the simulation (no RC)"
        )

    def _copter_mode(self, name: str | None) -> CommandHandle | int:
        """DO_SET_MODE to a Copter mode: what the simulated drone does in it."""
        copter, flying = self._v.copter, self._flying()
        refusal = copter.mode_refusal(name, self._v.latest.time, flying)
        if refusal is not None:
            return self._fail(refusal)
        if name == "AUTO":
            handle = self._v.mission.start()
            if not handle.done or handle.ok:
                copter.mode = name
            return handle
        if flying:
            if name == "LAND":
                handle = self._flight(self._v.drone.land)
            elif name == "RTL":
                handle = self._flight(self._v.drone.return_to_launch)
            else:  # GUIDED, LOITER, BRAKE...: stop where it is until told where to go
                handle = self._flight(self._v.drone.hold)
            if handle.done and not handle.ok:
                return handle
        copter.mode = name
        return mavlink.MAV_RESULT_ACCEPTED

    def _reposition(self, cmd: Command) -> CommandHandle | int:
        copter = self._v.copter
        if copter is not None and copter.mode != "GUIDED":
            if not int(cmd.params[1]) & mavlink.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE:
                return mavlink.MAV_RESULT_DENIED
            refusal = copter.mode_refusal("GUIDED", self._v.latest.time, self._flying())
            if refusal is not None:
                return self._fail(refusal)
            copter.mode = "GUIDED"
        tel = self._v.latest
        here = self._v.drone.world.to_geodetic(tel.position)
        lat = cmd.x if math.isfinite(cmd.x) else here[0]
        lon = cmd.y if math.isfinite(cmd.y) else here[1]
        if not math.isfinite(cmd.z):
            alt = here[2]
        elif cmd.frame in (mavlink.MAV_FRAME_GLOBAL, mavlink.MAV_FRAME_GLOBAL_INT):
            alt = cmd.z
        else:
            alt = cmd.z + self._v.home()[2]
        target = tuple(self._v.drone.world.to_enu(lat, lon, alt))
        yaw = None
        if math.isfinite(cmd.params[3]):
            heading = math.degrees(cmd.params[3])
            if int(cmd.params[1]) & mavlink.MAV_DO_REPOSITION_FLAGS_RELATIVE_YAW:
                yaw = tel.yaw - heading
            else:
                yaw = heading_to_yaw(heading)
        if cmd.params[0] > 0:
            self._v.speed_override = min(cmd.params[0], self._v.params.get("MPC_XY_VEL_MAX"))
        self._v.last_goto = (target, yaw)
        return self._flight(self._v.drone.goto, target, yaw, self._v.cruise_speed())

    def _change_speed(self, cmd: Command) -> int:
        speed = cmd.params[1]
        if speed == -1 or speed == -2:
            self._v.speed_override = None
        elif speed > 0:
            self._v.speed_override = min(speed, self._v.params.get("MPC_XY_VEL_MAX"))
        else:
            return mavlink.MAV_RESULT_DENIED
        tel = self._v.latest
        if self._v.last_goto is not None and tel.flight_mode == "HOLD" and not self._v.mission.active:
            target, yaw = self._v.last_goto  # still flying a reposition: carry on at the new speed
            if math.dist(target, tel.position) > 0.5:
                self._v.drone.goto(target, yaw, self._v.cruise_speed())
        return mavlink.MAV_RESULT_ACCEPTED

    def _mission_start(self, cmd: Command) -> CommandHandle:
        first = int(cmd.params[0]) if cmd.params[0] > 0 else None
        return self._v.mission.start(first)

    def _mission_current(self, cmd: Command) -> int:
        ok = self._v.mission.set_current(int(cmd.params[0]))
        return mavlink.MAV_RESULT_ACCEPTED if ok else mavlink.MAV_RESULT_DENIED

    # --- messages ----------------------------------------------------------------------------------
    def _set_interval(self, cmd: Command) -> int:
        msg_id, interval_us = int(cmd.params[0]), cmd.params[1]
        if msg_id == mavlink.MAVLINK_MSG_ID_HEARTBEAT or not self._v.streams.set_interval(msg_id, interval_us):
            return mavlink.MAV_RESULT_UNSUPPORTED
        return mavlink.MAV_RESULT_ACCEPTED

    def _get_interval(self, cmd: Command):
        msg_id = int(cmd.params[0])
        interval = self._v.streams.interval_us(msg_id)
        if interval is None:
            return mavlink.MAV_RESULT_UNSUPPORTED
        return lambda: self._v.mav.message_interval_send(msg_id, interval)

    def _request_message(self, cmd: Command):
        msg_id = int(cmd.params[0])
        if not self._v.encoder.supports(msg_id):
            return mavlink.MAV_RESULT_UNSUPPORTED
        return self._send_after(msg_id)

    def _autopilot_capabilities(self, cmd: Command):
        return self._send_after(mavlink.MAVLINK_MSG_ID_AUTOPILOT_VERSION)


def _sentence(reason: str) -> str:
    return reason[:1].upper() + reason[1:] if reason else reason
