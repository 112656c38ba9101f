"""Connection plumbing of the MAVSDK adapter: URL checks, telemetry rates, MAVSDK-to-aeroexec name maps and
forwarding MAVSDK's native log into Python ``logging``.
"""

from __future__ import annotations

import logging
import re
import threading
from dataclasses import dataclass

from aeroexec.drones.interface import LandedState
from mavsdk import LogLevel, log_subscribe
from mavsdk.asyncio.plugins.telemetry import FlightMode
from mavsdk.asyncio.plugins.telemetry import LandedState as MavsdkLandedState

native_logger = logging.getLogger("aeroexec.drones.mavsdk.native")

_NETWORK = re.compile(r"^(udpin|udpout|tcpin|tcpout|udp|tcp)://([^:/]*):(\d+)$")
_SERIAL = re.compile(r"^(serial|serial_flowcontrol)://(/?[^:]+)(:\d+)?$")
URL_EXAMPLES = "udpin://0.0.0.0:14540, tcpout://127.0.0.1:5760 or serial:///dev/ttyUSB0:57600"


@dataclass(frozen=True, slots=True)
class TelemetryRates:
    """Rates (Hz) the adapter asks the autopilot for; ArduPilot streams nothing unless asked. 0 leaves one alone."""

    position: float = 10.0  # GLOBAL_POSITION_INT: position and velocity
    attitude: float = 10.0  # ATTITUDE: yaw
    landed_state: float = 4.0  # EXTENDED_SYS_STATE
    health: float = 1.0  # SYS_STATUS: pre-arm and sensor health
    battery: float = 1.0
    gps_info: float = 1.0
    home: float = 0.5


def check_url(url: str) -> str:
    """The URL if MAVSDK can open that kind of connection; ValueError saying what is expected otherwise."""
    text = url.strip() if isinstance(url, str) else ""
    network = _NETWORK.match(text)
    if network:
        if not 0 < int(network.group(3)) < 65536:
            raise ValueError(f"bad MAVSDK connection URL {url!r}: port {network.group(3)} out of range")
        if network.group(1) in ("udpout", "tcpout", "tcp") and not network.group(2):
            raise ValueError(f"bad MAVSDK connection URL {url!r}: {network.group(1)} needs a host")
        return text
    if _SERIAL.match(text):
        return text
    raise ValueError(f"bad MAVSDK connection URL {url!r}: expected e.g. {URL_EXAMPLES}")


_LANDED = {
    MavsdkLandedState.UNKNOWN: LandedState.UNKNOWN,
    MavsdkLandedState.ON_GROUND: LandedState.ON_GROUND,
    MavsdkLandedState.IN_AIR: LandedState.IN_AIR,
    MavsdkLandedState.TAKING_OFF: LandedState.TAKING_OFF,
    MavsdkLandedState.LANDING: LandedState.LANDING,
}
_MODES = {
    FlightMode.RETURN_TO_LAUNCH: "RETURN",
    FlightMode.FOLLOW_ME: "FOLLOW_ME",
}
# MAVSDK names ArduCopter's modes after PX4's (flight_mode.cpp); these are the names ArduPilot's own ground
# stations show. Copter modes MAVSDK does not map (BRAKE, CIRCLE...) come as UNKNOWN.
_ARDUPILOT_MODES = {
    FlightMode.OFFBOARD: "GUIDED",
    FlightMode.HOLD: "LOITER",
    FlightMode.MISSION: "AUTO",
    FlightMode.RETURN_TO_LAUNCH: "RTL",
    FlightMode.LAND: "LAND",
    FlightMode.POSCTL: "POSHOLD",
    FlightMode.ALTCTL: "ALT_HOLD",
    FlightMode.STABILIZED: "STABILIZE",
    FlightMode.ACRO: "ACRO",
    FlightMode.FOLLOW_ME: "FOLLOW",
}


def landed_state(value) -> LandedState:
    return _LANDED.get(value, LandedState.UNKNOWN)


#: ArduCopter's mode numbers (HEARTBEAT custom_mode, ArduCopter/mode.h): MAVSDK reports BRAKE and LOITER both as
#: HOLD, so an ArduPilot's mode is read from its heartbeat.
COPTER_MODES = {0: "STABILIZE", 1: "ACRO", 2: "ALT_HOLD", 3: "AUTO", 4: "GUIDED", 5: "LOITER", 6: "RTL", 7: "CIRCLE",
                9: "LAND", 11: "DRIFT", 13: "SPORT", 14: "FLIP", 15: "AUTOTUNE", 16: "POSHOLD", 17: "BRAKE",
                18: "THROW", 19: "AVOID_ADSB", 20: "GUIDED_NOGPS", 21: "SMART_RTL", 22: "FLOWHOLD", 23: "FOLLOW",
                24: "ZIGZAG", 25: "SYSTEMID", 26: "AUTOROTATE", 27: "AUTO_RTL", 28: "TURTLE"}
COPTER_MODE_NUMBERS = {name: number for number, name in COPTER_MODES.items()}
_AUTOPILOT_INVALID = 8  # MAV_AUTOPILOT_INVALID: the heartbeat of a component that is no autopilot (a camera, a GCS)


def copter_mode_of(fields: dict) -> str | None:
    """The ArduCopter mode a HEARTBEAT's fields say, None for a heartbeat that is not an autopilot's."""
    if fields.get("autopilot", _AUTOPILOT_INVALID) == _AUTOPILOT_INVALID:
        return None
    number = int(fields.get("custom_mode", -1))
    return COPTER_MODES.get(number, f"MODE_{number}")


def flight_mode_name(mode, ardupilot: bool) -> str:
    """The interface's flight-mode name: PX4's as MAVSDK says them (HOLD, OFFBOARD, RETURN...), ArduPilot's as
    ArduPilot does (MAVSDK reports GUIDED as OFFBOARD and LOITER as HOLD: we say GUIDED and LOITER)."""
    if ardupilot:
        return _ARDUPILOT_MODES.get(mode, getattr(mode, "name", "UNKNOWN"))
    return _MODES.get(mode, getattr(mode, "name", "UNKNOWN"))


_log_lock = threading.Lock()
_log_installed = False
_LEVELS = {
    LogLevel.DEBUG: logging.DEBUG,
    LogLevel.INFO: logging.INFO,
    LogLevel.WARN: logging.WARNING,
    LogLevel.ERROR: logging.ERROR,
}


def forward_native_log() -> None:
    """Route MAVSDK's own log (printed to stdout by default) to the ``aeroexec.drones.mavsdk.native`` logger.

    MAVSDK has one log callback per process; the first adapter installs it, later calls do nothing.
    """
    global _log_installed
    with _log_lock:
        if _log_installed:
            return

        def forward(level, message, file, line) -> bool:
            native_logger.log(_LEVELS.get(level, logging.INFO), "%s", message)
            return True  # handled: MAVSDK does not print it

        log_subscribe(forward)
        _log_installed = True
