"""Drones: the drone interface, the simulated drone and world, and the MAVSDK adapter."""

from aeroexec.drones.interface import (
    CommandHandle,
    Drone,
    DroneEvent,
    Failure,
    LandedState,
    Observation,
    Telemetry,
    Vector,
)

__all__ = [
    "CommandHandle",
    "Drone",
    "DroneEvent",
    "Failure",
    "LandedState",
    "Observation",
    "Telemetry",
    "Vector",
]
