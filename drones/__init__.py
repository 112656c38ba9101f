"""Robots and drones: the robot interface (a drone is one kind), the simulated drone and world, the MAVSDK adapter.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from typing import TYPE_CHECKING

from aeroexec.lazy import lazy_names

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
