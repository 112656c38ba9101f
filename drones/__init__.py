"""Robots and drones: the robot interface (a drone is one kind), the simulated drone and world, the MAVSDK adapter."""

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

__all__ = [
    "CommandHandle",
    "Drone",
    "DroneEvent",
    "Failure",
    "LandedState",
    "Observation",
    "Robot",
    "Telemetry",
    "Vector",
]
