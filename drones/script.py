"""Flying a drone from a plain script: each call returns once the command's goal is reached (at the altitude, at
the point and slow, on the ground), not when the vehicle accepted the command as a ``CommandHandle`` does.

For drones that keep their own telemetry up to date (the MAVSDK adapter); inside the engine, behaviors
watch the telemetry at every tick instead, and never block.

    take_off(drone, 3.0)
    go_to(drone, (10.0, 0.0, 3.0))
    land(drone)
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from aeroexec.drones.interface import CommandHandle, Drone, LandedState, Telemetry, Vector

ACCEPT_TIMEOUT = 15.0  # wall seconds for the vehicle to accept a command
ALTITUDE_TOLERANCE = 0.3  # m
POSITION_TOLERANCE = 0.5  # m
SETTLED_SPEED = 0.3  # m/s
POLL = 0.05  # wall seconds between telemetry reads


class FlightError(RuntimeError):
    """A command the vehicle refused, or a goal not reached in time; the message says which and why."""


@dataclass(frozen=True)
class Reached:
    """What a call waited for, and the telemetry once it held."""

    goal: str
    telemetry: Telemetry
    seconds: float


def wait_until(drone: Drone, condition: Callable[[Telemetry], bool], timeout: float) -> Telemetry | None:
    """Poll the drone's telemetry until ``condition`` holds (that telemetry) or ``timeout`` wall seconds pass."""
    end = time.monotonic() + timeout
    while True:
        telemetry = drone.telemetry()
        if condition(telemetry):
            return telemetry
        if time.monotonic() >= end:
            return None
        time.sleep(POLL)


def _accepted(handle: CommandHandle) -> None:
    if not handle.wait(ACCEPT_TIMEOUT):
        raise FlightError(f"{handle.command}: the vehicle did not answer in {ACCEPT_TIMEOUT:g} s")
    if not handle.ok:
        raise FlightError(f"{handle.command} refused: {handle.reason}")


def _reach(drone: Drone, handle: CommandHandle, goal: str, condition: Callable[[Telemetry], bool],
           timeout: float) -> Reached:
    start = time.monotonic()
    _accepted(handle)
    telemetry = wait_until(drone, lambda t: condition(t) or not t.link_ok, timeout)
    if telemetry is None:
        last = drone.telemetry()
        raise FlightError(f"{handle.command}: not {goal} after {timeout:g} s (at {_fmt(last.position)}, "
                          f"{last.landed_state.value}, mode {last.flight_mode})")
    if not telemetry.link_ok:
        raise FlightError(f"{handle.command}: the link to the drone is lost")
    return Reached(goal, telemetry, time.monotonic() - start)


def take_off(drone: Drone, altitude: float, timeout: float = 60.0) -> Reached:
    """Take off and return once in the air at ``altitude`` meters above home."""
    return _reach(drone, drone.takeoff(altitude), f"at {altitude:g} m",
                  lambda t: t.landed_state is LandedState.IN_AIR
                  and abs(t.position[2] - altitude) <= ALTITUDE_TOLERANCE and t.speed < SETTLED_SPEED, timeout)


def go_to(drone: Drone, point: Vector, timeout: float = 120.0, tolerance: float = POSITION_TOLERANCE) -> Reached:
    """Fly to ``point`` (local ENU meters from home) and return once there and slow."""
    return _reach(drone, drone.goto(point), f"at {_fmt(point)}",
                  lambda t: math.dist(t.position, point) <= tolerance and t.speed < SETTLED_SPEED, timeout)


def land(drone: Drone, timeout: float = 120.0) -> Reached:
    """Land where the drone is and return once it is on the ground."""
    return _reach(drone, drone.land(), "on the ground", lambda t: t.landed_state is LandedState.ON_GROUND, timeout)


def _fmt(point: Vector) -> str:
    return "(" + ", ".join(f"{v:.1f}" for v in point) + ")"


__all__ = ["FlightError", "Reached", "go_to", "land", "take_off", "wait_until"]
