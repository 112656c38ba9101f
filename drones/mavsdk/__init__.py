"""The MAVSDK adapter: any MAVLink vehicle (PX4, ArduPilot, aeroexec sim) behind the drone interface."""

from .connection import TelemetryRates, check_url
from .drone import MavsdkDrone

__all__ = ["MavsdkDrone", "TelemetryRates", "check_url"]
