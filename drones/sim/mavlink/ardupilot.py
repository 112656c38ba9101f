"""ArduCopter's personality for the simulated MAVLink vehicle (``aeroexec sim --autopilot ardupilot``).

What differs from PX4, as ArduCopter 4.x does it: the heartbeat says ArduPilot (autopilot 3) with Copter mode
numbers; nothing but HEARTBEAT is streamed until a client asks (REQUEST_DATA_STREAM groups or
SET_MESSAGE_INTERVAL); the EKF comes up in steps (pre-arm checks pass, then the GPS origin and home are set,
announced once with HOME_POSITION); modes that navigate need that position; NAV_TAKEOFF only in GUIDED,
armed and landed, with its altitude above home; it refuses to arm in a mode that does not allow it (BRAKE,
LAND, RTL, SMART_RTL, CIRCLE, AUTO: ``Arm: Brake mode not armable``); offboard setpoints are GUIDED commands, and
when they stop for GUID_TIMEOUT the copter stops where it is.
"""

from __future__ import annotations

from dataclasses import dataclass

from pymavlink.dialects.v20 import ardupilotmega
from pymavlink.dialects.v20 import common as mavlink

#: Copter flight-mode numbers (ArduCopter/mode.h).
COPTER_MODES: dict[str, int] = {
    "STABILIZE": 0, "ACRO": 1, "ALT_HOLD": 2, "AUTO": 3, "GUIDED": 4, "LOITER": 5, "RTL": 6, "CIRCLE": 7,
    "LAND": 9, "DRIFT": 11, "SPORT": 13, "FLIP": 14, "AUTOTUNE": 15, "POSHOLD": 16, "BRAKE": 17, "THROW": 18,
    "AVOID_ADSB": 19, "GUIDED_NOGPS": 20, "SMART_RTL": 21, "FLOWHOLD": 22, "FOLLOW": 23, "ZIGZAG": 24,
}
COPTER_MODE_NAMES = {number: name for name, number in COPTER_MODES.items()}
#: Modes that need a position estimate to be entered or armed in.
NAVIGATING = {"AUTO", "GUIDED", "LOITER", "RTL", "CIRCLE", "POSHOLD", "BRAKE", "SMART_RTL", "FOLLOW", "ZIGZAG"}
#: Modes the simulation can enter without a pilot on the sticks only while disarmed.
PILOTED = {"STABILIZE", "ACRO", "ALT_HOLD", "POSHOLD", "SPORT", "DRIFT", "FLOWHOLD"}
#: Modes ArduCopter refuses to arm in (their ``allows_arming`` is false: AUTO without AUTO_OPTIONS too).
NOT_ARMABLE = {"BRAKE", "LAND", "RTL", "SMART_RTL", "CIRCLE", "AUTO"}
_GUIDED_FLAG = {"AUTO", "RTL", "LOITER", "GUIDED", "CIRCLE", "POSHOLD", "BRAKE", "SMART_RTL", "FOLLOW"}

M = mavlink
A = ardupilotmega
EKF_STATUS_REPORT = A.MAVLINK_MSG_ID_EKF_STATUS_REPORT  # ArduPilot's own message (ardupilotmega.xml)
_EKF_ATTITUDE = A.EKF_ATTITUDE | A.EKF_VELOCITY_HORIZ | A.EKF_VELOCITY_VERT | A.EKF_POS_VERT_ABS
_EKF_POSITION = A.EKF_POS_HORIZ_REL | A.EKF_POS_HORIZ_ABS | A.EKF_PRED_POS_HORIZ_REL | A.EKF_PRED_POS_HORIZ_ABS
#: REQUEST_DATA_STREAM groups and the messages of each that the simulation produces (GCS_MAVLink streams).
DATA_STREAMS: dict[int, tuple[int, ...]] = {
    M.MAV_DATA_STREAM_EXTENDED_STATUS: (M.MAVLINK_MSG_ID_SYS_STATUS, M.MAVLINK_MSG_ID_GPS_RAW_INT,
                                        M.MAVLINK_MSG_ID_MISSION_CURRENT),
    M.MAV_DATA_STREAM_POSITION: (M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT, M.MAVLINK_MSG_ID_LOCAL_POSITION_NED),
    M.MAV_DATA_STREAM_EXTRA1: (M.MAVLINK_MSG_ID_ATTITUDE,),
    M.MAV_DATA_STREAM_EXTRA2: (M.MAVLINK_MSG_ID_VFR_HUD,),
    M.MAV_DATA_STREAM_EXTRA3: (M.MAVLINK_MSG_ID_BATTERY_STATUS, M.MAVLINK_MSG_ID_SYSTEM_TIME, EKF_STATUS_REPORT),
}
#: Messages that say where the vehicle is: not sent before the EKF has its origin.
NEEDS_ORIGIN = {M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT, M.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
                M.MAVLINK_MSG_ID_HOME_POSITION}
GUIDED_TIMEOUT_S = 3.0  # GUID_TIMEOUT: velocity setpoints older than this stop the copter


def streamed_messages(stream_id: int) -> tuple[int, ...]:
    """The messages a REQUEST_DATA_STREAM for ``stream_id`` turns on or off (ALL: every group)."""
    if stream_id == M.MAV_DATA_STREAM_ALL:
        return tuple(msg for group in DATA_STREAMS.values() for msg in group)
    return DATA_STREAMS.get(stream_id, ())


@dataclass
class ArduCopter:
    """The copter's mode and EKF state. Times are the simulation's seconds since the vehicle started."""

    prearm_s: float = 2.0  # the pre-arm checks pass (SYS_STATUS PREARM_CHECK healthy): armable
    origin_s: float = 5.0  # the EKF uses GPS: origin and home set, global position good
    mode: str = "STABILIZE"
    boot: float | None = None
    origin_announced: bool = False

    def __post_init__(self) -> None:
        if not 0.0 <= self.prearm_s <= self.origin_s:
            raise ValueError(f"the EKF delays must satisfy 0 <= prearm ({self.prearm_s}) <= origin ({self.origin_s})")

    def uptime(self, now: float) -> float:
        if self.boot is None:
            self.boot = now
        return now - self.boot

    def prearm_ok(self, now: float) -> bool:
        return self.uptime(now) >= self.prearm_s

    def position_ok(self, now: float) -> bool:
        return self.uptime(now) >= self.origin_s

    def ekf_flags(self, now: float) -> int:
        """EKF_STATUS_REPORT flags: attitude and velocity once the pre-arm checks pass, position with the origin."""
        if not self.prearm_ok(now):
            return 0
        if not self.position_ok(now):
            return _EKF_ATTITUDE | A.EKF_CONST_POS_MODE
        return _EKF_ATTITUDE | _EKF_POSITION

    def arm_refusal(self, now: float) -> str | None:
        """Why ArduCopter would refuse to arm now (its STATUSTEXT), None when it may."""
        if not self.prearm_ok(now):
            return "PreArm: EKF3 waiting for GPS config data"
        if self.mode in NOT_ARMABLE:  # as ArduCopter's mandatory checks say it (AP_Arming_Copter)
            return f"Arm: {self.mode.capitalize()} mode not armable"
        if self.mode in NAVIGATING and not self.position_ok(now):
            return "PreArm: Need Position Estimate"
        return None

    def mode_refusal(self, name: str | None, now: float, flying: bool) -> str | None:
        """Why a DO_SET_MODE to ``name`` fails (STATUSTEXT), None when it may be entered."""
        if name is None:
            return "Flight mode change failed: unknown mode"
        if name in NAVIGATING and not self.position_ok(now):
            return f"Flight mode change failed: {name} requires position"
        if name in PILOTED and flying:
            return f"Flight mode change failed: {name} needs a pilot (no RC in the simulation)"
        if name not in NAVIGATING | PILOTED | {"LAND"}:
            return f"Flight mode change failed: {name} is not simulated"
        return None

    def reported(self, sim_mode: str, mission_active: bool) -> str:
        """The Copter mode to report, following what the simulated drone does on its own (failsafe LAND, RTL)."""
        if mission_active:
            self.mode = "AUTO"
        elif sim_mode == "LAND":
            self.mode = "LAND"
        elif sim_mode == "RETURN":
            self.mode = "RTL"
        elif sim_mode in ("OFFBOARD", "TAKEOFF"):
            self.mode = "GUIDED"
        return self.mode

    def heartbeat_fields(self, mode: str, armed: bool) -> tuple[int, int, int]:
        """(autopilot, base_mode, custom_mode) of a HEARTBEAT in ``mode``."""
        base = (M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
                | M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED)
        if mode in _GUIDED_FLAG:
            base |= M.MAV_MODE_FLAG_GUIDED_ENABLED
        if armed:
            base |= M.MAV_MODE_FLAG_SAFETY_ARMED
        return M.MAV_AUTOPILOT_ARDUPILOTMEGA, base, COPTER_MODES.get(mode, 0)
