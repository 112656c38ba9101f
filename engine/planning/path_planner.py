"""Path planning free of obstacles: A* on a 3D occupancy grid built from an obstacle map, with line-of-sight pruning.

Pure geometry (no engine state): the map only has to answer ``distance_to_obstacle(point)`` (meters to the nearest
surface, 0 inside) and may carry ``bounds`` (``lower``/``upper`` or ``min``/``max`` corners). Paths keep ``margin``
meters from every obstacle: a grid cell is free when its center is at least ``margin`` plus half a cell diagonal away,
so every 26-connected step between free cells keeps the margin, and every shortcut is checked on the distance
function itself (sphere tracing), never on the grid.
"""

from __future__ import annotations

import dataclasses
import heapq
import itertools
import logging
import math
from collections.abc import Sequence

from aeroexec.engine.planning.grid import (
    SQRT2,
    SQRT3,
    ObstacleMap,
    OccupancyGrid,
    PlannerSettings,
    Point,
    inside,
    map_bounds,
    occupancy_grid,
    point,
    segment_clear,
)

logger = logging.getLogger(__name__)


class PathPlanner:
    """Plans paths in one obstacle map; ``plan(start, goal)`` returns waypoints after ``start`` up to ``goal``."""

    def __init__(self, obstacles: ObstacleMap, settings: PlannerSettings | None = None,
                 bounds: tuple[Sequence[float], Sequence[float]] | None = None) -> None:
        self.obstacles = obstacles
        self.settings = settings or PlannerSettings()
        self.bounds = (point(bounds[0]), point(bounds[1])) if bounds is not None else map_bounds(obstacles)
        self.reason = ""  # why the last plan is empty
        self.expanded = 0  # cells the last search expanded

    def grid(self, start: Point | None = None, goal: Point | None = None) -> OccupancyGrid:
        """The occupancy grid the planner searches (built or taken from the cache)."""
        lower, upper = self._box(start, goal)
        return occupancy_grid(self.obstacles, lower, upper, self.settings)

    def _box(self, start: Point | None, goal: Point | None) -> tuple[Point, Point]:
        """The map's bounds, or a box ``padding`` around start and goal (from the ground up) without them."""
        if self.bounds is not None:
            return self.bounds
        pad, points = self.settings.padding, [p for p in (start, goal) if p is not None] or [(0.0, 0.0, 0.0)]
        low = [math.floor(min(p[a] for p in points) - pad) for a in range(3)]
        high = [math.ceil(max(p[a] for p in points) + pad) for a in range(3)]
        return (low[0], low[1], min(0.0, *(p[2] for p in points))), (high[0], high[1], high[2])

    def clearance(self, point: Point) -> float:
        return self.obstacles.distance_to_obstacle(point)

    def plan(self, start: Sequence[float], goal: Sequence[float]) -> list[Point]:
        """Waypoints from ``start`` (excluded) to ``goal`` keeping the margin, or [] (see :attr:`reason`)."""
        start, goal = point(start), point(goal)
        quick = self.quick(start, goal)
        if quick is not None:
            return quick
        lower, upper = self._box(start, goal)
        start_margin = self._start_margin(start)
        settings = self.settings
        for attempt in range(settings.refinements + 1):
            if attempt:  # thin passages close at a coarse resolution: look again at a finer one
                settings = dataclasses.replace(settings, resolution=settings.resolution / 2.0)
                logger.info("%s; trying again at %.3g m", self.reason, settings.resolution)
            path = self._plan_on(occupancy_grid(self.obstacles, lower, upper, settings), start, goal, start_margin)
            if path:
                return path
        return self._none(self.reason)

    def _start_margin(self, start: Point) -> float:
        """A drone already nearer than the margin may still leave with less."""
        margin, clearance = self.settings.margin, self.clearance(start)
        return margin if clearance >= margin else 0.9 * clearance

    def quick(self, start: Sequence[float], goal: Sequence[float]) -> list[Point] | None:
        """The answer when it needs no grid search (a few distance queries): [] with :attr:`reason` for a goal out
        of bounds or too near an obstacle, ``[goal]`` for a clear straight line; None when a search must decide."""
        start, goal = point(start), point(goal)
        margin = self.settings.margin
        self.reason, self.expanded = "", 0
        lower, upper = self._box(start, goal)
        if not inside(goal, lower, upper):
            return self._none(f"the destination {goal} is outside the bounds {lower}-{upper}")
        if self.clearance(goal) < margin:
            return self._none(f"the destination {goal} is inside an obstacle or closer than {margin:g} m to one")
        if not inside(start, lower, upper):
            return self._none(f"the start {start} is outside the bounds {lower}-{upper}")
        if math.dist(start, goal) < 1e-9:
            return [goal]
        if segment_clear(self.obstacles, start, goal, self._start_margin(start)):
            return [goal]
        return None

    def _plan_on(self, grid: OccupancyGrid, start: Point, goal: Point, start_margin: float) -> list[Point]:
        first = self._connect(grid, start, start_margin)
        last = self._connect(grid, goal, self.settings.margin)
        if first is None or last is None:
            which, point = ("start", start) if first is None else ("destination", goal)
            self.reason = f"no free space within reach of the {which} {point}"
            return []
        reachable = {grid.component(c) for c in last}
        first = [c for c in first if grid.component(c) in reachable]
        if not first:
            self.reason = f"the destination {goal} cannot be reached from {start} (it is enclosed)"
            return []
        cells = self._search(grid, first, set(last), goal)
        if cells is None:  # cannot happen when the components agree; kept as a guard
            self.reason = f"no path from {start} to {goal}"
            return []
        return self._shortcut([start, *(grid.center(c) for c in cells), goal], start_margin)

    def _none(self, reason: str) -> list[Point]:
        self.reason = reason
        logger.info("no path: %s", reason)
        return []

    def _connect(self, grid: OccupancyGrid, point: Point, margin: float) -> list[int] | None:
        """Free cells near ``point`` joined to it by a clear segment: its own cell, else the nearest within 3 cells."""
        home = grid.index(point)
        if home is not None and grid.free(home):
            return [home]
        r, candidates = grid.resolution, set()
        for di, dj, dk in itertools.product(range(-3, 4), repeat=3):
            cell = grid.index((point[0] + di * r, point[1] + dj * r, point[2] + dk * r))
            if cell is not None and grid.free(cell):
                candidates.add((math.dist(point, grid.center(cell)), cell))
        found = [cell for _, cell in sorted(candidates)
                 if segment_clear(self.obstacles, point, grid.center(cell), margin)]
        return found[:8] or None

    def _search(self, grid: OccupancyGrid, sources: list[int], targets: set[int], goal: Point) -> list[int] | None:
        """A* over the 26-connected free cells with the octile heuristic: the cells from a source to a target."""
        nx, nxy, cells, r = grid.NX, grid.NX * grid.NY, grid.cells, grid.resolution
        moves = [(di + dj * nx + dk * nxy, r * math.sqrt(di * di + dj * dj + dk * dk))
                 for dk in (-1, 0, 1) for dj in (-1, 0, 1) for di in (-1, 0, 1) if di or dj or dk]
        gi, gj, gk = ((p - lo) / r + 0.5 for p, lo in zip(goal, grid.lower, strict=True))
        c1, c2, c3 = r, r * (SQRT2 - 1.0), r * (SQRT3 - SQRT2)

        def heuristic(index: int) -> float:
            k, rest = divmod(index, nxy)
            j, i = divmod(rest, nx)
            a, b, c = sorted((abs(i - gi), abs(j - gj), abs(k - gk)))
            return c1 * c + c2 * b + c3 * a

        cost: dict[int, float] = {}
        came: dict[int, int] = {}
        heap: list[tuple[float, float, int]] = []
        for s in sources:
            cost[s] = 0.0
            heapq.heappush(heap, (heuristic(s), 0.0, s))
        closed = set()
        while heap:
            _, g, current = heapq.heappop(heap)
            g = -g
            if current in closed:
                continue
            closed.add(current)
            if current in targets:
                self.expanded = len(closed)
                path = [current]
                while path[-1] in came:
                    path.append(came[path[-1]])
                return path[::-1]
            for offset, step in moves:
                nxt = current + offset
                if not cells[nxt] or nxt in closed:
                    continue
                new = g + step
                if new < cost.get(nxt, math.inf):
                    cost[nxt] = new
                    came[nxt] = current
                    heapq.heappush(heap, (new + heuristic(nxt), -new, nxt))
        self.expanded = len(closed)
        return None

    def _shortcut(self, points: list[Point], start_margin: float) -> list[Point]:
        """Line-of-sight pruning: from each kept point, jump to the farthest later point in clear view."""
        margin = self.settings.margin
        kept, anchor = [], 0
        while anchor < len(points) - 1:
            m = start_margin if anchor == 0 else margin
            best = anchor + 1  # consecutive points are joined safely by construction
            for j in range(len(points) - 1, anchor + 1, -1):
                if segment_clear(self.obstacles, points[anchor], points[j], m):
                    best = j
                    break
            kept.append(points[best])
            anchor = best
        return kept


def plan_path(obstacles: ObstacleMap | None, start: Sequence[float], goal: Sequence[float],
              settings: PlannerSettings | None = None) -> list[Point]:
    """A path from ``start`` (excluded) to ``goal`` clear of ``obstacles`` by the margin, or [] when there is none.

    Without a map (None) the path is the straight line: ``[goal]``.
    """
    if obstacles is None:
        return [point(goal)]
    return PathPlanner(obstacles, settings).plan(start, goal)
