"""Obstacle solids of the simulated world: axis-aligned boxes and vertical cylinders, with their geometry.

Each solid answers three questions in local ENU meters: the signed distance from a point to its surface
(negative inside), whether a straight segment passes through it, and whether a point lies inside it.
``signed_distances`` answers the first for many points at once (numpy arrays of shape (N, 3)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

Vector = tuple[float, float, float]

_EPS = 1e-12


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned box: ``center`` and full ``size`` (x, y, z extents) in meters."""

    name: str
    center: Vector
    size: Vector

    @property
    def lower(self) -> Vector:
        return tuple(c - s / 2.0 for c, s in zip(self.center, self.size, strict=True))  # type: ignore[return-value]

    @property
    def upper(self) -> Vector:
        return tuple(c + s / 2.0 for c, s in zip(self.center, self.size, strict=True))  # type: ignore[return-value]

    def signed_distance(self, point: Vector) -> float:
        """Meters from ``point`` to the surface; negative inside."""
        d = [abs(p - c) - s / 2.0 for p, c, s in zip(point, self.center, self.size, strict=True)]
        outside = math.sqrt(sum(max(v, 0.0) ** 2 for v in d))
        inside = min(max(d[0], d[1], d[2]), 0.0)
        return outside + inside

    def signed_distances(self, points: Any) -> Any:
        """:meth:`signed_distance` of every row of ``points`` (an (N, 3) array), as an (N,) array."""
        import numpy as np

        d = np.abs(points - np.asarray(self.center)) - np.asarray(self.size) / 2.0
        out = np.maximum(d, 0.0)
        outside = np.sqrt(out[:, 0] ** 2 + out[:, 1] ** 2 + out[:, 2] ** 2)
        return outside + np.minimum(np.maximum(np.maximum(d[:, 0], d[:, 1]), d[:, 2]), 0.0)

    def segment_hits(self, a: Vector, b: Vector) -> bool:
        """Whether the segment from ``a`` to ``b`` touches the box (slab test)."""
        t0, t1 = 0.0, 1.0
        for lo, hi, pa, pb in zip(self.lower, self.upper, a, b, strict=True):
            d = pb - pa
            if abs(d) < _EPS:
                if pa < lo or pa > hi:
                    return False
                continue
            ta, tb = (lo - pa) / d, (hi - pa) / d
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
            if t0 > t1:
                return False
        return True


@dataclass(frozen=True, slots=True)
class Cylinder:
    """A vertical cylinder standing on ``base`` (m up) at ``center`` (x, y), ``radius`` and ``height`` meters."""

    name: str
    center: tuple[float, float]
    radius: float
    height: float
    base: float = 0.0

    @property
    def top(self) -> float:
        return self.base + self.height

    def signed_distance(self, point: Vector) -> float:
        """Meters from ``point`` to the surface; negative inside."""
        radial = math.hypot(point[0] - self.center[0], point[1] - self.center[1]) - self.radius
        half = self.height / 2.0
        vertical = abs(point[2] - (self.base + half)) - half
        outside = math.hypot(max(radial, 0.0), max(vertical, 0.0))
        return outside + min(max(radial, vertical), 0.0)

    def signed_distances(self, points: Any) -> Any:
        """:meth:`signed_distance` of every row of ``points`` (an (N, 3) array), as an (N,) array."""
        import numpy as np

        radial = np.hypot(points[:, 0] - self.center[0], points[:, 1] - self.center[1]) - self.radius
        half = self.height / 2.0
        vertical = np.abs(points[:, 2] - (self.base + half)) - half
        outside = np.hypot(np.maximum(radial, 0.0), np.maximum(vertical, 0.0))
        return outside + np.minimum(np.maximum(radial, vertical), 0.0)

    def segment_hits(self, a: Vector, b: Vector) -> bool:
        """Whether the segment from ``a`` to ``b`` touches the cylinder."""
        # Parameter interval where the segment is within the height range.
        t0, t1 = 0.0, 1.0
        dz = b[2] - a[2]
        if abs(dz) < _EPS:
            if a[2] < self.base or a[2] > self.top:
                return False
        else:
            ta, tb = (self.base - a[2]) / dz, (self.top - a[2]) / dz
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
            if t0 > t1:
                return False
        # Parameter interval where the segment is within the radius (a quadratic in t).
        ox, oy = a[0] - self.center[0], a[1] - self.center[1]
        dx, dy = b[0] - a[0], b[1] - a[1]
        qa = dx * dx + dy * dy
        qc = ox * ox + oy * oy - self.radius * self.radius
        if qa < _EPS:
            return qc <= 0.0
        qb = 2.0 * (ox * dx + oy * dy)
        disc = qb * qb - 4.0 * qa * qc
        if disc < 0.0:
            return False
        root = math.sqrt(disc)
        ra, rb = (-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)
        return max(t0, ra) <= min(t1, rb)


Obstacle = Box | Cylinder


def bounding_box(obstacle: Obstacle) -> tuple[Vector, Vector]:
    """The (lower, upper) corners of the axis-aligned box around a solid."""
    if isinstance(obstacle, Box):
        return obstacle.lower, obstacle.upper
    (cx, cy), r = obstacle.center, obstacle.radius
    return (cx - r, cy - r, obstacle.base), (cx + r, cy + r, obstacle.top)


class ObstacleIndex:
    """A broad phase for collision checks: the solids whose bounding box, grown by ``reach``, meets each ``cell``-meter
    column of a horizontal grid, so a point is tested only against the few solids near it."""

    def __init__(self, obstacles: tuple[Obstacle, ...] | list[Obstacle], reach: float, cell: float = 4.0) -> None:
        self.obstacles = tuple(obstacles)
        self.reach = reach
        self.cell = cell
        columns: dict[tuple[int, int], list[Obstacle]] = {}
        self._heights: dict[int, tuple[float, float]] = {}
        for obstacle in self.obstacles:  # in the world's order, so the first solid touched is the world's first
            (x0, y0, z0), (x1, y1, z1) = bounding_box(obstacle)
            self._heights[id(obstacle)] = (z0 - reach, z1 + reach)
            for i in range(math.floor((x0 - reach) / cell), math.floor((x1 + reach) / cell) + 1):
                for j in range(math.floor((y0 - reach) / cell), math.floor((y1 + reach) / cell) + 1):
                    columns.setdefault((i, j), []).append(obstacle)
        self._columns = {key: tuple(found) for key, found in columns.items()}

    def collides(self, point: Vector, radius: float) -> Obstacle | None:
        """The first solid a sphere of ``radius`` (at most :attr:`reach`) at ``point`` touches, or None."""
        if radius > self.reach:
            return next((o for o in self.obstacles if o.signed_distance(point) < radius), None)
        near = self._columns.get((math.floor(point[0] / self.cell), math.floor(point[1] / self.cell)))
        if not near:
            return None
        z = point[2]
        for obstacle in near:
            low, high = self._heights[id(obstacle)]
            if low <= z <= high and obstacle.signed_distance(point) < radius:
                return obstacle
        return None
