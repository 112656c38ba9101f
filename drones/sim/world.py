"""The simulated world: home point, geofence bounds, obstacles, ArUco markers, objects and a moving platform.

A :class:`World` is an immutable record with the geometric queries the simulated drone, its camera and the
engine's predicates need. Worlds come from YAML files (:mod:`~aeroexec.drones.sim.world_file`) or the packaged default.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

from aeroexec.drones.geodesy import Geodetic, enu_to_geodetic, geodetic_to_enu
from aeroexec.drones.sim.geofence import Fence, breach
from aeroexec.drones.sim.shapes import Box, Cylinder, Obstacle

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

Vector = tuple[float, float, float]
DECK_RADIUS = 0.75  # m: a platform's landing deck unless its world file says otherwise

__all__ = [
    "Bounds",
    "Box",
    "CameraSettings",
    "Cylinder",
    "Frame",
    "Marker",
    "Obstacle",
    "Platform",
    "World",
    "WorldError",
    "WorldObject",
]


class WorldError(ValueError):
    """A world file that cannot be used; the message starts with ``file:line:`` when it can."""


@dataclass(frozen=True, slots=True)
class Bounds:
    """The geofence: an ENU box the drone must stay in."""

    lower: Vector
    upper: Vector

    def contains(self, point: Vector) -> bool:
        lower, upper = self.lower, self.upper
        return (lower[0] <= point[0] <= upper[0] and lower[1] <= point[1] <= upper[1]
                and lower[2] <= point[2] <= upper[2])

    def clamp(self, point: Vector, margin: float = 0.0) -> Vector:
        """The point of the bounds (shrunk by ``margin`` where possible) nearest to ``point``."""
        out = []
        for lo, p, hi in zip(self.lower, point, self.upper, strict=True):
            m = min(margin, (hi - lo) / 2.0)
            out.append(min(max(p, lo + m), hi - m))
        return tuple(out)  # type: ignore[return-value]


@dataclass(frozen=True, slots=True)
class Marker:
    """An ArUco marker: ``id`` (0..1023), ``position``, and the direction its face looks at.

    ``yaw`` (degrees, 0 = east, counterclockwise) and ``pitch`` (degrees, 0 = horizontal, 90 = facing up).
    """

    id: int
    position: Vector
    yaw: float = 0.0
    pitch: float = 0.0
    name: str = ""

    @property
    def normal(self) -> Vector:
        y, p = math.radians(self.yaw), math.radians(self.pitch)
        return (math.cos(p) * math.cos(y), math.cos(p) * math.sin(y), math.sin(p))


@dataclass(frozen=True, slots=True)
class Frame:
    """A named frame of the world (a model's frame in a simulator's world: ``gate_0/link``): its origin
    ``position`` (ENU meters from home) and its orientation ``rpy`` (roll, pitch, yaw in radians, ENU: yaw 0 looks
    east, counterclockwise), as a simulator's world file places the model."""

    name: str
    position: Vector
    rpy: Vector = (0.0, 0.0, 0.0)

    def to_world(self, point: Vector) -> Vector:
        """A point given in this frame, in the world's ENU meters from home."""
        (cr, sr), (cp, sp), (cy, sy) = ((math.cos(a), math.sin(a)) for a in self.rpy)
        x, y, z = point
        rotated = (cy * cp * x + (cy * sp * sr - sy * cr) * y + (cy * sp * cr + sy * sr) * z,
                   sy * cp * x + (sy * sp * sr + cy * cr) * y + (sy * sp * cr - cy * sr) * z,
                   -sp * x + cp * sr * y + cp * cr * z)
        return tuple(round(p + r, 6) for p, r in zip(self.position, rotated, strict=True))  # type: ignore[return-value]


@dataclass(frozen=True, slots=True)
class WorldObject:
    """A colored, shaped object a camera can recognize (not an obstacle)."""

    name: str
    color: str
    shape: str
    position: Vector


@dataclass(frozen=True, slots=True)
class Platform:
    """A platform moving along ``path`` (ENU points) at ``speed`` m/s, looping or going back and forth.

    An optional ArUco ``marker_id`` lies on its deck, facing up. The deck is a disc of ``deck_radius`` m
    around ``position(t)`` (its height is the path's z): a drone can land on it and ride along.
    """

    name: str
    path: tuple[Vector, ...]
    speed: float
    loop: bool = True
    marker_id: int | None = None
    deck_radius: float = DECK_RADIUS

    def velocity(self, t: float, dt: float = 0.02) -> Vector:
        """The platform's velocity (m/s) over the ``dt`` seconds before ``t`` (at ``t`` itself from the start)."""
        t0 = max(t - dt, 0.0)
        t1 = t0 + dt
        a, b = self.position(t0), self.position(t1)
        return tuple((q - p) / dt for p, q in zip(a, b, strict=True))  # type: ignore[return-value]

    def position(self, t: float) -> Vector:
        """Where the platform is at time ``t`` (seconds from the start of the simulation)."""
        try:
            points, legs, total = _legs(self.path, self.loop)
        except TypeError:  # a path given as lists: not hashable, so not cached
            points, legs, total = _legs.__wrapped__(self.path, self.loop)
        if total <= 0.0 or self.speed <= 0.0:
            return points[0]
        s = max(t, 0.0) * self.speed
        if self.loop:
            s = math.fmod(s, total)
        else:  # back and forth
            s = math.fmod(s, 2.0 * total)
            if s > total:
                s = 2.0 * total - s
        for a, b, length in legs:
            if s <= length and length > 0.0:
                f = s / length
                return tuple(pa + (pb - pa) * f for pa, pb in zip(a, b, strict=True))  # type: ignore[return-value]
            s -= length
        return points[-1]


@functools.lru_cache(maxsize=64)
def _legs(path: tuple[Vector, ...], loop: bool) -> tuple[list[Vector], list[tuple[Vector, Vector, float]], float]:
    """A platform path's points (closed when it loops), legs with their lengths, and total length."""
    points = list(path)
    if loop and len(points) > 1:
        points.append(points[0])
    legs = [(a, b, math.dist(a, b)) for a, b in zip(points, points[1:], strict=False)]
    return points, legs, sum(length for _, _, length in legs)


@dataclass(frozen=True, slots=True)
class CameraSettings:
    """The simulated camera: fields of view (degrees), range (m), mounting pitch (degrees, negative = down)."""

    hfov: float = 80.0
    vfov: float = 60.0
    range: float = 12.0
    pitch: float = -20.0


@dataclass(frozen=True)
class World:
    """Everything the simulated drone flies in; coordinates are ENU meters from ``home``."""

    home: Geodetic
    bounds: Bounds
    obstacles: tuple[Obstacle, ...] = ()
    markers: tuple[Marker, ...] = ()
    objects: tuple[WorldObject, ...] = ()
    platform: Platform | None = None
    camera: CameraSettings = field(default_factory=CameraSettings)
    payload: tuple[str, ...] = ()  # names of the items the drone carries at the start
    name: str = "world"
    source: str | None = None  # the file it was loaded from
    fences: tuple[Fence, ...] = ()  # inclusion and exclusion zones inside the bounds (a plan's geofence)
    frames: tuple[Frame, ...] = ()  # named frames a mission may give points in (a simulator world's models)
    #: where named drones start (east, north meters from home), as a simulator's world config spawns them
    starts: tuple[tuple[str, tuple[float, float]], ...] = ()

    # --- frames ----------------------------------------------------------------------------------
    def to_geodetic(self, enu: Vector) -> Geodetic:
        """(latitude, longitude, altitude m AMSL) of an ENU point."""
        return enu_to_geodetic(enu, self.home)

    def to_enu(self, lat: float, lon: float, alt: float) -> Vector:
        """ENU meters from home of a geodetic point."""
        return geodetic_to_enu((lat, lon, alt), self.home)

    # --- geometry --------------------------------------------------------------------------------
    def inside(self, point: Vector) -> bool:
        """Whether ``point`` is within the bounds and the fences (the geofence)."""
        return self.bounds.contains(point) and (not self.fences or breach(self.fences, point[:2]) is None)

    def why_outside(self, point: Vector) -> str | None:
        """Why ``point`` breaks the geofence: outside the bounds, or a fence's (None when it is inside)."""
        if not self.bounds.contains(point):
            lower, upper = self.bounds.lower, self.bounds.upper
            box = ", ".join(f"{axis} {lo:g}..{hi:g}" for axis, lo, hi in zip("xyz", lower, upper, strict=True))
            return f"outside the world's bounds ({box}; geofence)"
        why = breach(self.fences, point[:2]) if self.fences else None
        return f"{why} (geofence)" if why else None

    def collides(self, point: Vector, radius: float = 0.0) -> Obstacle | None:
        """The first obstacle a sphere of ``radius`` at ``point`` touches, or None."""
        for obstacle in self.obstacles:
            if obstacle.signed_distance(point) < radius:
                return obstacle
        return None

    def distance_to_obstacle(self, point: Vector) -> float:
        """Meters from ``point`` to the nearest obstacle surface (0 inside one, inf without obstacles)."""
        if not self.obstacles:
            return math.inf
        return max(min(o.signed_distance(point) for o in self.obstacles), 0.0)

    def distances_to_obstacle(self, points: Any) -> Any:
        """:meth:`distance_to_obstacle` of every row of ``points`` (an (N, 3) numpy array) at once."""
        import numpy as np

        points = np.asarray(points, dtype=float)
        if not self.obstacles:
            return np.full(len(points), math.inf)
        nearest = self.obstacles[0].signed_distances(points)
        for obstacle in self.obstacles[1:]:
            nearest = np.minimum(nearest, obstacle.signed_distances(points))
        return np.maximum(nearest, 0.0)

    def segment_clear(self, a: Vector, b: Vector) -> bool:
        """Whether the straight segment from ``a`` to ``b`` passes through no obstacle (line of sight)."""
        return not any(o.segment_hits(a, b) for o in self.obstacles)

    def platform_position(self, t: float) -> Vector | None:
        """Where the moving platform is at time ``t``, or None when the world has none."""
        return None if self.platform is None else self.platform.position(t)

    def marker(self, marker_id: int) -> Marker | None:
        return next((m for m in self.markers if m.id == marker_id), None)
