"""Robots and drones: the robot interface (a drone is one kind), the simulated drone and world, the MAVSDK adapter.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["CommandHandle", "Drone", "DroneEvent", "Failure", "LandedState", "Observation", "Robot", "Telemetry",
           "Vector"]
__getattr__ = lazy_names(__name__, {"CommandHandle": "interface", "Drone": "interface", "DroneEvent": "interface",
                                    "Failure": "interface", "LandedState": "interface", "Observation": "interface",
                                    "Robot": "interface", "Telemetry": "interface", "Vector": "interface"})

if TYPE_CHECKING:
    from aeroexec.drones.interface import (
        CommandHandle,
        Drone,
        DroneEvent,
        Failure,
        LandedState,
        Observation,
        Robot,
        Telemetry,
        Vector,
    )
