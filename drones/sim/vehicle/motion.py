"""Kinematic control laws of the simulated multicopter: velocity toward a target with speed, acceleration
and braking limits, velocity tracking, and rate-limited yaw. Pure functions on tuples, one substep each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from aeroexec.drones.angles import wrap180

Vector = tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Limits:
    """Speeds (m/s) and accelerations (m/s^2) one manoeuvre may use."""

    horizontal_speed: float
    climb_rate: float
    descent_rate: float
    horizontal_acceleration: float
    vertical_acceleration: float
    position_gain: float  # 1/s, the final approach


def turn_yaw(yaw: float, target: float, max_rate: float, dt: float) -> float:
    """``yaw`` turned toward ``target`` by at most ``max_rate * dt`` degrees, the short way round."""
    error = wrap180(target - yaw)
    step = max_rate * dt
    return wrap180(target if abs(error) <= step else yaw + math.copysign(step, error))


def heading_to(origin: Vector, target: Vector) -> float | None:
    """ENU yaw (degrees) from ``origin`` to ``target`` in the horizontal plane, None when right above it."""
    dx, dy = target[0] - origin[0], target[1] - origin[1]
    if math.hypot(dx, dy) < 1e-6:
        return None
    return math.degrees(math.atan2(dy, dx))


def desired_velocity(position: Vector, velocity: Vector, target: Vector, limits: Limits, dt: float) -> Vector:
    """The next velocity on the straight line to ``target``: as fast as limits allow while still able to stop on it.

    The speed along the line changes by at most one step of the acceleration limits, so from rest the
    drone flies a straight line; motion across the line is left to :func:`accelerate` to damp.
    (Run every substep: minima and maxima are written out as comparisons, in ``min``'s and ``max``'s order.)
    """
    dx, dy, dz = target[0] - position[0], target[1] - position[1], target[2] - position[2]
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    if dist < 1e-9:
        return (0.0, 0.0, 0.0)
    ux, uy, uz = dx / dist, dy / dist, dz / dist
    uh = math.hypot(ux, uy)
    speed = accel = math.inf
    if uh > 1e-9:
        speed = limits.horizontal_speed / uh
        accel = limits.horizontal_acceleration / uh
    if uz > 1e-9 or uz < -1e-9:
        uv = abs(uz)
        vertical = (limits.climb_rate if uz > 0.0 else limits.descent_rate) / uv
        if vertical < speed:
            speed = vertical
        vertical = limits.vertical_acceleration / uv
        if vertical < accel:
            accel = vertical
    braking = math.sqrt(2.0 * accel * dist)
    if braking < speed:
        speed = braking
    approach = limits.position_gain * dist
    if approach < speed:
        speed = approach
    along = velocity[0] * ux + velocity[1] * uy + velocity[2] * uz
    if along < 0.0:
        along = 0.0
    change = accel * dt
    slowest, fastest = along - change, along + change
    if slowest > speed:
        speed = slowest
    if fastest < speed:
        speed = fastest
    return (ux * speed, uy * speed, uz * speed)


def accelerate(velocity: Vector, desired: Vector, limits: Limits, dt: float) -> Vector:
    """``velocity`` moved toward ``desired`` within the horizontal and vertical acceleration limits."""
    vx, vy, vz = velocity
    dx, dy, dz = desired[0] - vx, desired[1] - vy, desired[2] - vz
    dh = math.hypot(dx, dy)
    max_h = limits.horizontal_acceleration * dt
    if dh > max_h:
        dx, dy = dx * max_h / dh, dy * max_h / dh
    max_z = limits.vertical_acceleration * dt
    if -max_z > dz:
        dz = -max_z
    if max_z < dz:
        dz = max_z
    return (vx + dx, vy + dy, vz + dz)


def clamp_velocity(velocity: Vector, limits: Limits) -> Vector:
    """A commanded velocity within the horizontal speed, climb and descent limits."""
    vx, vy, vz = velocity
    h = math.hypot(vx, vy)
    if h > limits.horizontal_speed:
        vx, vy = vx * limits.horizontal_speed / h, vy * limits.horizontal_speed / h
    return (vx, vy, min(max(vz, -limits.descent_rate), limits.climb_rate))


def stopping_point(position: Vector, velocity: Vector, limits: Limits) -> Vector:
    """Where the drone comes to rest braking at full deceleration from ``velocity``."""
    vh = math.hypot(velocity[0], velocity[1])
    bh = vh / (2.0 * limits.horizontal_acceleration)
    bz = abs(velocity[2]) / (2.0 * limits.vertical_acceleration)
    return (position[0] + velocity[0] * bh, position[1] + velocity[1] * bh, position[2] + velocity[2] * bz)
