"""Exploration planning with memory: lawnmower coverage of a region, handing out the next point not yet covered.

A region is the corners of a polygon at an altitude (three or more points; the altitude is their mean height) or the
two opposite corners of a box (swept at its middle height). Sweep lines run east-west, ``spacing`` apart (the camera
footprint less an overlap), alternating direction; points on a line are at most ``spacing`` apart. A point is covered
once the drone comes within ``reach`` of it. Pure geometry: the obstacle map, when given, only removes points closer
than ``margin`` to an obstacle.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

logger = logging.getLogger(__name__)

Point = tuple[float, float, float]


@dataclass(frozen=True)
class ExplorationSettings:
    """``footprint``: width (m) of ground the camera sees across the track; ``overlap``: fraction shared by two sweeps;
    ``reach``: distance (m) at which a point counts as covered; ``max_attempts``: times a point is handed out before it
    is given up as unreachable; ``margin``: clearance (m) a point needs from obstacles."""

    footprint: float = 6.0
    overlap: float = 0.2
    reach: float = 1.0
    max_attempts: int = 3
    margin: float = 1.0

    @property
    def spacing(self) -> float:
        return max(0.1, self.footprint * (1.0 - self.overlap))


def region_key(region: Sequence[Sequence[float]]) -> tuple[Point, ...]:
    """A hashable name for a region (its corners rounded to the centimeter)."""
    return tuple((round(float(p[0]), 2), round(float(p[1]), 2), round(float(p[2]), 2)) for p in region)


def _polygon(region: Sequence[Sequence[float]]) -> tuple[list[tuple[float, float]], float]:
    corners = [(float(p[0]), float(p[1]), float(p[2]) if len(p) > 2 else 0.0) for p in region]
    if len(corners) < 2:
        raise ValueError(f"a region needs at least two corners, not {len(corners)}")
    altitude = sum(c[2] for c in corners) / len(corners)
    if len(corners) == 2:  # opposite corners of a box
        (x0, y0, _), (x1, y1, _) = corners
        xa, xb, ya, yb = min(x0, x1), max(x0, x1), min(y0, y1), max(y0, y1)
        return [(xa, ya), (xb, ya), (xb, yb), (xa, yb)], altitude
    return [(c[0], c[1]) for c in corners], altitude


def _crossings(polygon: list[tuple[float, float]], y: float) -> list[float]:
    """Where the horizontal line at ``y`` crosses the polygon's edges, sorted (half-open rule at vertices)."""
    xs = []
    for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1], strict=True):
        if (y0 <= y < y1) or (y1 <= y < y0):
            xs.append(x0 + (y - y0) * (x1 - x0) / (y1 - y0))
    return sorted(xs)


def lawnmower(region: Sequence[Sequence[float]], spacing: float) -> list[Point]:
    """Boustrophedon coverage points of a region: east-west lines ``spacing`` apart, points at most ``spacing`` apart.

    Lines and points are inset by half a spacing from the border; a piece narrower than that gets its middle point.
    """
    if not spacing > 0:
        raise ValueError(f"the sweep spacing must be positive, not {spacing}")
    polygon, altitude = _polygon(region)
    ys = [y for _, y in polygon]
    y_low, y_high = min(ys), max(ys)
    lines = max(1, math.ceil((y_high - y_low) / spacing - 1e-9))
    points: list[Point] = []
    for n in range(lines):
        y = y_low + (n + 0.5) * (y_high - y_low) / lines
        xs = _crossings(polygon, y)
        pieces = []
        for a, b in zip(xs[0::2], xs[1::2], strict=False):
            inset = min(spacing / 2.0, (b - a) / 2.0)
            a, b = a + inset, b - inset
            count = max(1, math.ceil((b - a) / spacing - 1e-9) + 1) if b > a else 1
            pieces.append([a + (b - a) * i / (count - 1) for i in range(count)] if count > 1 else [(a + b) / 2.0])
        row = [x for piece in pieces for x in piece]
        if n % 2:
            row.reverse()
        points.extend((round(x, 3), round(y, 3), round(altitude, 3)) for x in row)
    return points


def _sweeps(points: list[Point]) -> list[list[Point]]:
    """The four ways to fly a lawnmower: either line first, either direction on the first line."""
    rows: list[list[Point]] = []
    for point in points:
        if rows and rows[-1][0][1] == point[1]:
            rows[-1].append(point)
        else:
            rows.append([point])
    mirrored = [row[::-1] for row in rows]
    forward, other = [p for row in rows for p in row], [p for row in mirrored for p in row]
    return [forward, forward[::-1], other, other[::-1]]


class ExplorationPlanner:
    """The coverage of one region and how far it has got; :meth:`next_point` hands out the next uncovered point."""

    def __init__(self, region: Sequence[Sequence[float]], settings: ExplorationSettings | None = None,
                 obstacles: Any = None) -> None:
        self.region = region_key(region)
        self.settings = settings or ExplorationSettings()
        points = lawnmower(region, self.settings.spacing)
        if obstacles is not None:
            kept = [p for p in points if obstacles.distance_to_obstacle(p) >= self.settings.margin]
            if len(kept) < len(points):
                logger.info("exploration of %s: %d of %d points are too near obstacles and left out",
                            self.region, len(points) - len(kept), len(points))
            points = kept
        self.points: list[Point] = points
        self.covered = [False] * len(points)
        self.attempts = [0] * len(points)
        self.skipped: list[Point] = []
        self._oriented = False

    @property
    def remaining(self) -> int:
        return self.covered.count(False)

    @property
    def done(self) -> bool:
        return self.remaining == 0

    def mark(self, position: Sequence[float]) -> int:
        """Cover every point within reach of ``position``; returns how many became covered."""
        reach, newly = self.settings.reach, 0
        for n, point in enumerate(self.points):
            if not self.covered[n] and math.dist(point, position) <= reach:
                self.covered[n] = True
                newly += 1
        return newly

    def next_point(self, position: Sequence[float] | None = None) -> Point | None:
        """The next point to explore from ``position`` (covering what is within reach first), or None when done.

        The first call starts the sweep at the corner nearest ``position``; a point handed out ``max_attempts`` times
        without being reached is given up.
        """
        if position is not None:
            position = tuple(float(v) for v in position)
            if not self._oriented and self.points and not any(self.covered):
                self.points = min(_sweeps(self.points), key=lambda sweep: math.dist(position, sweep[0]))
            self.mark(position)
        self._oriented = True
        for n, point in enumerate(self.points):
            if self.covered[n]:
                continue
            if self.attempts[n] >= self.settings.max_attempts:
                logger.warning("exploration of %s: giving up %s, not reached after %d attempts",
                               self.region, point, self.attempts[n])
                self.covered[n] = True
                self.skipped.append(point)
                continue
            self.attempts[n] += 1
            return point
        return None


class ExplorationStore:
    """The exploration planners of a run, one per region, so consecutive requests continue the same coverage."""

    def __init__(self, settings: ExplorationSettings | None = None, obstacles: Any = None) -> None:
        self.settings = settings or ExplorationSettings()
        self.obstacles = obstacles
        self._planners: dict[tuple[Point, ...], ExplorationPlanner] = {}

    def planner(self, region: Sequence[Sequence[float]]) -> ExplorationPlanner:
        key = region_key(region)
        found = self._planners.get(key)
        if found is None:
            found = self._planners[key] = self.new_planner(region)
        return found

    def has(self, region: Sequence[Sequence[float]]) -> bool:
        """Whether the region's coverage is already planned."""
        return region_key(region) in self._planners

    def new_planner(self, region: Sequence[Sequence[float]]) -> ExplorationPlanner:
        """A fresh coverage of the region, not yet kept (the planning worker builds it; :meth:`adopt` keeps it)."""
        return ExplorationPlanner(region, self.settings, self.obstacles)

    def adopt(self, planner: ExplorationPlanner) -> None:
        """Keep a coverage built by :meth:`new_planner`, unless the region already has one."""
        self._planners.setdefault(planner.region, planner)

    def mark(self, position: Sequence[float]) -> None:
        """Cover, in every region being explored, the points within reach of ``position``."""
        for planner in self._planners.values():
            if not planner.done:
                planner.mark(position)

    def forget(self, region: Sequence[Sequence[float]] | None = None) -> None:
        """Start a region's exploration (every region's, without one) afresh."""
        if region is None:
            self._planners.clear()
        else:
            self._planners.pop(region_key(region), None)
