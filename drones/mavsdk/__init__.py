"""The MAVSDK adapter: any MAVLink vehicle (PX4, ArduPilot, aeroexec sim) behind the drone interface.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["MavsdkDrone", "TelemetryRates", "check_url"]
__getattr__ = lazy_names(__name__, {"TelemetryRates": "connection", "check_url": "connection", "MavsdkDrone": "drone"})

if TYPE_CHECKING:
    from aeroexec.drones.mavsdk.connection import TelemetryRates, check_url
    from aeroexec.drones.mavsdk.drone import MavsdkDrone
