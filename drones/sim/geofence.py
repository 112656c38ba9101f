"""A geofence in the world's frame: inclusion and exclusion polygons and circles (a plan's geofence, a world's).

A point is allowed when it is inside at least one inclusion fence (when there is any) and inside no exclusion
fence, as PX4 reads a plan's fence; positions are ENU meters from the world's home, fences are checked in the
horizontal plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Point = tuple[float, float]


@dataclass(frozen=True)
class Fence:
    """One fence: a polygon (``vertices``) or a circle (``center``, ``radius``); ``line`` where the file has it."""

    inclusion: bool
    vertices: tuple[Point, ...] = ()
    center: Point | None = None
    radius: float = 0.0
    line: int = 0

    @property
    def kind(self) -> str:
        return f"{'inclusion' if self.inclusion else 'exclusion'} {'circle' if self.center else 'polygon'}"

    def contains(self, point: Point) -> bool:
        if self.center is not None:
            return math.dist(point, self.center) <= self.radius
        return _in_polygon(point, self.vertices)


def _in_polygon(point: Point, vertices: tuple[Point, ...]) -> bool:
    """Even-odd rule (a point on an edge counts as inside)."""
    x, y = point
    inside = False
    count = len(vertices)
    for i in range(count):
        (x1, y1), (x2, y2) = vertices[i], vertices[(i + 1) % count]
        if _on_segment(point, (x1, y1), (x2, y2)):
            return True
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def _on_segment(p: Point, a: Point, b: Point, tolerance: float = 1e-6) -> bool:
    cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
    if abs(cross) > tolerance * max(1.0, math.dist(a, b)):
        return False
    return min(a[0], b[0]) - tolerance <= p[0] <= max(a[0], b[0]) + tolerance and \
        min(a[1], b[1]) - tolerance <= p[1] <= max(a[1], b[1]) + tolerance


def breach(fences: list[Fence], point: Point) -> str | None:
    """Why ``point`` breaks the geofence (None when it does not)."""
    inclusions = [f for f in fences if f.inclusion]
    if inclusions and not any(f.contains(point) for f in inclusions):
        lines = ", ".join(f"line {f.line}" for f in inclusions if f.line)
        return f"outside every inclusion fence ({lines})" if lines else "outside every inclusion fence"
    for fence in fences:
        if not fence.inclusion and fence.contains(point):
            return f"inside the {fence.kind}" + (f" of line {fence.line}" if fence.line else "")
    return None
