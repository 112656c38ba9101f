"""The MAVSDK adapter: any MAVLink vehicle (PX4, ArduPilot, aeroexec sim) behind the drone interface.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from typing import TYPE_CHECKING

from aeroexec.lazy import lazy_names

__all__ = ["MavsdkDrone", "TelemetryRates", "check_url"]
__getattr__ = lazy_names(__name__, {"TelemetryRates": "connection", "check_url": "connection", "MavsdkDrone": "drone"})

if TYPE_CHECKING:
    from aeroexec.drones.mavsdk.connection import TelemetryRates, check_url
    from aeroexec.drones.mavsdk.drone import MavsdkDrone
