"""PX4-style MAVLink output of the simulated vehicle: flight-mode encoding and the telemetry messages MAVSDK reads.

Positions come from the simulated drone's ENU state; the local NED frame has its origin at home, as PX4's
does once it has a GPS fix at the take-off point. Rates are chosen by the vehicle; this module only encodes.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from aeroexec.drones.interface import LandedState, Telemetry
from aeroexec.drones.sim.mavlink.ardupilot import EKF_STATUS_REPORT
from pymavlink.dialects.v20 import common as mavlink

# PX4 custom mode (px4_custom_mode.h): main mode in bits 16..23, sub mode (AUTO only) in bits 24..31.
_MODE_TO_PX4: dict[str, tuple[int, int]] = {
    "MANUAL": (1, 0),
    "ALTCTL": (2, 0),
    "POSCTL": (3, 0),
    "READY": (4, 1),
    "TAKEOFF": (4, 2),
    "HOLD": (4, 3),
    "MISSION": (4, 4),
    "RETURN": (4, 5),
    "LAND": (4, 6),
    "ACRO": (5, 0),
    "OFFBOARD": (6, 0),
    "STABILIZED": (7, 0),
}
_PX4_TO_MODE = {value: name for name, value in _MODE_TO_PX4.items()}
PX4_MAIN_AUTO = 4

GPS_ACCURACY_MM = 800  # mm: the simulated receiver's horizontal accuracy (1 sigma), reported in GPS_RAW_INT
_LANDED_TO_MAV = {
    LandedState.UNKNOWN: mavlink.MAV_LANDED_STATE_UNDEFINED,
    LandedState.ON_GROUND: mavlink.MAV_LANDED_STATE_ON_GROUND,
    LandedState.TAKING_OFF: mavlink.MAV_LANDED_STATE_TAKEOFF,
    LandedState.IN_AIR: mavlink.MAV_LANDED_STATE_IN_AIR,
    LandedState.LANDING: mavlink.MAV_LANDED_STATE_LANDING,
}

# Messages the vehicle can stream or send on request, with PX4-like default rates (Hz, wall time; 0 = off).
DEFAULT_RATES_HZ: dict[int, float] = {
    mavlink.MAVLINK_MSG_ID_SYS_STATUS: 1.0,
    mavlink.MAVLINK_MSG_ID_EXTENDED_SYS_STATE: 2.0,
    mavlink.MAVLINK_MSG_ID_GPS_RAW_INT: 2.0,
    mavlink.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: 10.0,
    mavlink.MAVLINK_MSG_ID_LOCAL_POSITION_NED: 10.0,
    mavlink.MAVLINK_MSG_ID_ATTITUDE: 10.0,
    mavlink.MAVLINK_MSG_ID_ATTITUDE_QUATERNION: 0.0,
    mavlink.MAVLINK_MSG_ID_BATTERY_STATUS: 1.0,
    mavlink.MAVLINK_MSG_ID_HOME_POSITION: 0.5,
    mavlink.MAVLINK_MSG_ID_VFR_HUD: 4.0,
    mavlink.MAVLINK_MSG_ID_SYSTEM_TIME: 0.0,
    mavlink.MAVLINK_MSG_ID_MISSION_CURRENT: 1.0,
}
# Sent only when asked for (REQUEST_MESSAGE), never streamed.
ON_REQUEST_ONLY = {mavlink.MAVLINK_MSG_ID_AUTOPILOT_VERSION}

_SENSORS = (
    mavlink.MAV_SYS_STATUS_SENSOR_3D_GYRO
    | mavlink.MAV_SYS_STATUS_SENSOR_3D_ACCEL
    | mavlink.MAV_SYS_STATUS_SENSOR_3D_MAG
    | mavlink.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
    | mavlink.MAV_SYS_STATUS_SENSOR_GPS
    | mavlink.MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
    | mavlink.MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION
    | mavlink.MAV_SYS_STATUS_SENSOR_YAW_POSITION
    | mavlink.MAV_SYS_STATUS_SENSOR_Z_ALTITUDE_CONTROL
    | mavlink.MAV_SYS_STATUS_SENSOR_XY_POSITION_CONTROL
    | mavlink.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
    | mavlink.MAV_SYS_STATUS_AHRS
    | mavlink.MAV_SYS_STATUS_SENSOR_BATTERY
    | mavlink.MAV_SYS_STATUS_PREARM_CHECK
)

_CAPABILITIES = (
    mavlink.MAV_PROTOCOL_CAPABILITY_MISSION_FLOAT
    | mavlink.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
    | mavlink.MAV_PROTOCOL_CAPABILITY_MISSION_INT
    | mavlink.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
    | mavlink.MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE
    | mavlink.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_LOCAL_NED
    | mavlink.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_GLOBAL_INT
    | mavlink.MAV_PROTOCOL_CAPABILITY_MAVLINK2
)
_FLIGHT_SW_VERSION = (1 << 24) | (15 << 16) | (0 << 8) | 255  # reported as PX4 v1.15.0 release


def px4_custom_mode(mode: str) -> int:
    """The heartbeat ``custom_mode`` of a flight mode name (unknown names read as AUTO.LOITER)."""
    main, sub = _MODE_TO_PX4.get(mode, _MODE_TO_PX4["HOLD"])
    return (main << 16) | (sub << 24)


def mode_from_px4(main: int, sub: int) -> str | None:
    """The flight mode name of a PX4 main/sub mode pair, None when the simulation has no such mode."""
    if main != PX4_MAIN_AUTO:
        sub = 0
    return _PX4_TO_MODE.get((int(main), int(sub)))


def yaw_to_heading(yaw_deg: float) -> float:
    """ENU yaw (0 = east, counterclockwise) to compass heading in [0, 360) (0 = north, clockwise)."""
    return (90.0 - yaw_deg) % 360.0


def heading_to_yaw(heading_deg: float) -> float:
    """Compass heading to ENU yaw in (-180, 180]."""
    yaw = (90.0 - heading_deg) % 360.0
    return yaw - 360.0 if yaw > 180.0 else yaw


@dataclass(frozen=True, slots=True)
class VehicleState:
    """What one round of output is made of: the simulated drone's telemetry and what the vehicle adds to it."""

    telemetry: Telemetry
    geodetic: tuple[float, float, float]  # latitude, longitude, altitude AMSL of the drone
    home: tuple[float, float, float]  # latitude, longitude, altitude AMSL of home
    mode: str  # the flight mode the vehicle reports (MISSION while running a mission)
    armable: bool
    yaw_rate: float  # deg/s, ENU (counterclockwise)
    mission_seq: int = 0
    mission_total: int = 0
    position_ok: bool = True  # the estimator has a global position (SYS_STATUS GPS healthy, a 3D fix)
    heartbeat: tuple[int, int, int] | None = None  # (autopilot, base_mode, custom_mode); None: PX4's
    ekf_flags: int = 0  # ArduPilot's EKF_STATUS_REPORT flags


class TelemetryEncoder:
    """Sends the vehicle's MAVLink messages through one pymavlink ``MAVLink`` encoder."""

    def __init__(self, mav: mavlink.MAVLink, uid: int = 0x5E1A_E0E0) -> None:
        self._mav = mav
        self._uid = uid
        self._senders = {
            mavlink.MAVLINK_MSG_ID_HEARTBEAT: self.heartbeat,
            mavlink.MAVLINK_MSG_ID_SYS_STATUS: self._sys_status,
            mavlink.MAVLINK_MSG_ID_EXTENDED_SYS_STATE: self._extended_sys_state,
            mavlink.MAVLINK_MSG_ID_GPS_RAW_INT: self._gps_raw_int,
            mavlink.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: self._global_position_int,
            mavlink.MAVLINK_MSG_ID_LOCAL_POSITION_NED: self._local_position_ned,
            mavlink.MAVLINK_MSG_ID_ATTITUDE: self._attitude,
            mavlink.MAVLINK_MSG_ID_ATTITUDE_QUATERNION: self._attitude_quaternion,
            mavlink.MAVLINK_MSG_ID_BATTERY_STATUS: self._battery_status,
            mavlink.MAVLINK_MSG_ID_HOME_POSITION: self._home_position,
            mavlink.MAVLINK_MSG_ID_VFR_HUD: self._vfr_hud,
            mavlink.MAVLINK_MSG_ID_SYSTEM_TIME: self._system_time,
            mavlink.MAVLINK_MSG_ID_AUTOPILOT_VERSION: self._autopilot_version,
            mavlink.MAVLINK_MSG_ID_MISSION_CURRENT: self._mission_current,
        }
        if hasattr(mav, "ekf_status_report_send"):  # an ArduPilot (ardupilotmega dialect) encoder
            self._senders[EKF_STATUS_REPORT] = self._ekf_status_report

    def heartbeat(self, state: VehicleState) -> None:
        tel = state.telemetry
        status = mavlink.MAV_STATE_ACTIVE if tel.armed else mavlink.MAV_STATE_STANDBY
        if state.heartbeat is not None:
            autopilot, base, custom = state.heartbeat
            self._mav.heartbeat_send(mavlink.MAV_TYPE_QUADROTOR, autopilot, base, custom, status)
            return
        base = mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | mavlink.MAV_MODE_FLAG_STABILIZE_ENABLED
        if state.mode in ("HOLD", "TAKEOFF", "LAND", "RETURN", "MISSION", "OFFBOARD", "READY"):
            base |= mavlink.MAV_MODE_FLAG_GUIDED_ENABLED | mavlink.MAV_MODE_FLAG_AUTO_ENABLED
        if tel.armed:
            base |= mavlink.MAV_MODE_FLAG_SAFETY_ARMED
        self._mav.heartbeat_send(
            mavlink.MAV_TYPE_QUADROTOR, mavlink.MAV_AUTOPILOT_PX4, base, px4_custom_mode(state.mode), status
        )

    def statustext(self, severity: int, text: str) -> None:
        """STATUSTEXT, split in 50-byte chunks (with an id) when longer."""
        data = text.encode("utf-8", "replace")
        if len(data) <= 50:
            self._mav.statustext_send(severity, data)
            return
        msg_id = (hash(text) & 0xFFFE) + 1
        chunks = [data[i : i + 50] for i in range(0, len(data), 50)]
        for seq, chunk in enumerate(chunks):
            self._mav.statustext_send(severity, chunk, msg_id, seq)

    def send(self, msg_id: int, state: VehicleState) -> bool:
        """Send one message by id; False when the vehicle does not produce that message."""
        sender = self._senders.get(msg_id)
        if sender is None:
            return False
        sender(state)
        return True

    def supports(self, msg_id: int) -> bool:
        return msg_id in self._senders

    @staticmethod
    def _boot_ms(state: VehicleState) -> int:
        return int(max(state.telemetry.time, 0.0) * 1000) & 0xFFFFFFFF

    def _sys_status(self, state: VehicleState) -> None:
        tel = state.telemetry
        health = _SENSORS
        if not state.armable:
            health &= ~mavlink.MAV_SYS_STATUS_PREARM_CHECK
        if not state.position_ok:
            health &= ~mavlink.MAV_SYS_STATUS_SENSOR_GPS
        enabled = _SENSORS if tel.armed else _SENSORS & ~mavlink.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
        self._mav.sys_status_send(
            _SENSORS,
            enabled,
            health,
            250,
            int(tel.battery_voltage * 1000),
            -1,
            int(round(tel.battery_percent)),
            0,
            0,
            0,
            0,
            0,
            0,
        )

    def _extended_sys_state(self, state: VehicleState) -> None:
        landed = _LANDED_TO_MAV.get(state.telemetry.landed_state, mavlink.MAV_LANDED_STATE_UNDEFINED)
        self._mav.extended_sys_state_send(mavlink.MAV_VTOL_STATE_UNDEFINED, landed)

    def _gps_raw_int(self, state: VehicleState) -> None:
        """GPS_RAW_INT with the fix's horizontal and vertical accuracy (an RTK-less GNSS receiver's)."""
        lat, lon, alt = state.geodetic
        vx, vy, _ = state.telemetry.velocity
        ground = math.hypot(vx, vy)
        cog = int(yaw_to_heading(math.degrees(math.atan2(vy, vx))) * 100) if ground > 0.2 else 65535
        self._mav.gps_raw_int_send(
            int(state.telemetry.time * 1e6),
            mavlink.GPS_FIX_TYPE_3D_FIX if state.position_ok else mavlink.GPS_FIX_TYPE_NO_FIX,
            _e7(lat),
            _e7(lon),
            int(alt * 1000),
            80,
            120,
            int(ground * 100),
            cog,
            14 if state.position_ok else 0,
            int(alt * 1000),  # above the ellipsoid: the simulated geoid is the ellipsoid
            GPS_ACCURACY_MM if state.position_ok else 0xFFFFFFFF,  # h_acc: what the adapter believes of it
            2 * GPS_ACCURACY_MM if state.position_ok else 0xFFFFFFFF,  # v_acc
        )

    def _global_position_int(self, state: VehicleState) -> None:
        tel = state.telemetry
        lat, lon, alt = state.geodetic
        vx, vy, vz = tel.velocity
        heading = int(yaw_to_heading(tel.yaw) * 100) % 36000
        self._mav.global_position_int_send(
            self._boot_ms(state),
            _e7(lat),
            _e7(lon),
            int(alt * 1000),
            int(tel.position[2] * 1000),
            int(vy * 100),
            int(vx * 100),
            int(-vz * 100),
            heading,
        )

    def _local_position_ned(self, state: VehicleState) -> None:
        tel = state.telemetry
        x, y, z = tel.position
        vx, vy, vz = tel.velocity
        self._mav.local_position_ned_send(self._boot_ms(state), y, x, -z, vy, vx, -vz)

    def _attitude(self, state: VehicleState) -> None:
        yaw = _wrap_pi(math.radians(yaw_to_heading(state.telemetry.yaw)))
        self._mav.attitude_send(self._boot_ms(state), 0.0, 0.0, yaw, 0.0, 0.0, -math.radians(state.yaw_rate))

    def _attitude_quaternion(self, state: VehicleState) -> None:
        half = _wrap_pi(math.radians(yaw_to_heading(state.telemetry.yaw))) / 2.0
        self._mav.attitude_quaternion_send(
            self._boot_ms(state), math.cos(half), 0.0, 0.0, math.sin(half), 0.0, 0.0, -math.radians(state.yaw_rate)
        )

    def _battery_status(self, state: VehicleState) -> None:
        tel = state.telemetry
        voltages = [min(int(tel.battery_voltage * 1000), 65534)] + [65535] * 9
        self._mav.battery_status_send(
            0,
            mavlink.MAV_BATTERY_FUNCTION_ALL,
            mavlink.MAV_BATTERY_TYPE_LIPO,
            32767,
            voltages,
            -1,
            -1,
            -1,
            int(round(tel.battery_percent)),
        )

    def _home_position(self, state: VehicleState) -> None:
        lat, lon, alt = state.home
        self._mav.home_position_send(
            _e7(lat),
            _e7(lon),
            int(alt * 1000),
            0.0,
            0.0,
            0.0,
            [1.0, 0.0, 0.0, 0.0],
            0.0,
            0.0,
            0.0,
            int(state.telemetry.time * 1e6),
        )

    def _vfr_hud(self, state: VehicleState) -> None:
        tel = state.telemetry
        vx, vy, vz = tel.velocity
        ground = math.hypot(vx, vy)
        throttle = 50 if tel.armed and tel.landed_state != LandedState.ON_GROUND else 0
        self._mav.vfr_hud_send(ground, ground, int(yaw_to_heading(tel.yaw)) % 360, throttle, state.geodetic[2], vz)

    def _system_time(self, state: VehicleState) -> None:
        self._mav.system_time_send(int(time.time() * 1e6), self._boot_ms(state))

    def _autopilot_version(self, state: VehicleState) -> None:
        self._mav.autopilot_version_send(
            _CAPABILITIES, _FLIGHT_SW_VERSION, 0, 0, 0, [0] * 8, [0] * 8, [0] * 8, 0, 0, self._uid
        )

    def _ekf_status_report(self, state: VehicleState) -> None:
        good = 0.1 if state.position_ok else 1.0  # variances: small when the estimate is good
        self._mav.ekf_status_report_send(state.ekf_flags, good, good, 0.1, 0.1, 0.0)

    def _mission_current(self, state: VehicleState) -> None:
        self._mav.mission_current_send(state.mission_seq, state.mission_total)


def _e7(degrees: float) -> int:
    return int(round(degrees * 1e7))


def _wrap_pi(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
