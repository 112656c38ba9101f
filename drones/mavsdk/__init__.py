"""The MAVSDK adapter: any MAVLink vehicle (PX4, ArduPilot, aeroexec sim) behind the drone interface."""

from aeroexec.drones.mavsdk.connection import TelemetryRates, check_url
from aeroexec.drones.mavsdk.drone import MavsdkDrone

__all__ = ["MavsdkDrone", "TelemetryRates", "check_url"]
