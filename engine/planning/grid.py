"""The 3D occupancy grid of an obstacle map for path planning: free cells keep a margin from every surface.

Pure geometry (no engine state): the map only has to answer ``distance_to_obstacle(point)`` (meters to the nearest
surface, 0 inside) and may carry ``bounds``. A cell is free when its center is at least ``margin`` plus half a cell
diagonal away, so every 26-connected step between free cells keeps the margin. A map that also answers
``distances_to_obstacle(points)`` for an (N, 3) numpy array (the simulated world does) is classified with numpy, a
layer of cells at a time; other maps by splitting blocks of cells until the distance decides. Grids are built when
first asked for and cached per map and box.
"""
from __future__ import annotations

import logging
import math
import threading
from bisect import bisect_right
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

logger = logging.getLogger(__name__)

Point = tuple[float, float, float]

SQRT2, SQRT3 = math.sqrt(2.0), math.sqrt(3.0)
_TOLERANCE = 1e-3  # m: a segment closer than margin + this to an obstacle is refused


class ObstacleMap(Protocol):
    """What the planner needs of a map (the simulated world satisfies it)."""

    def distance_to_obstacle(self, point: Point) -> float: ...


@dataclass(frozen=True)
class PlannerSettings:
    """``resolution``: grid cell (m); ``margin``: clearance to obstacles (drone radius + safety, m);
    ``bounds_margin``: clearance to the bounds' faces for grid cells; ``max_cells``: the grid is coarsened past it;
    ``padding``: room around start and goal when the map has no bounds; ``refinements``: how many times a search that
    finds no path is tried again at half the resolution (passages narrower than twice the margin plus a cell
    diagonal are closed on a grid)."""

    resolution: float = 0.5
    margin: float = 1.0
    bounds_margin: float = 0.5
    max_cells: int = 4_000_000
    padding: float = 10.0
    refinements: int = 1


def map_bounds(obstacles: Any) -> tuple[Point, Point] | None:
    """The (lower, upper) corners of a map's ``bounds`` attribute, or None when it has none."""
    bounds = getattr(obstacles, "bounds", None)
    if bounds is None:
        return None
    for low, high in (("lower", "upper"), ("min", "max")):
        if hasattr(bounds, low) and hasattr(bounds, high):
            return point(getattr(bounds, low)), point(getattr(bounds, high))
    if isinstance(bounds, Sequence) and len(bounds) == 2:
        return point(bounds[0]), point(bounds[1])
    return None


def point(value: Sequence[float]) -> Point:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


def inside(point: Point, lower: Point, upper: Point) -> bool:
    return all(lo - 1e-9 <= p <= hi + 1e-9 for lo, p, hi in zip(lower, point, upper, strict=True))


def segment_clear(obstacles: ObstacleMap, a: Point, b: Point, margin: float) -> bool:
    """Whether every point of segment ``a``-``b`` is at least ``margin`` from every obstacle.

    Sphere tracing: at a point ``d`` meters from the nearest obstacle, the next ``d - margin`` meters are safe
    (the distance is 1-Lipschitz), so this is exact up to a millimeter and needs few queries away from obstacles.
    """
    length = math.dist(a, b)
    t = 0.0
    while True:
        p = (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t) if length else a
        room = obstacles.distance_to_obstacle(p) - margin
        if room < _TOLERANCE:
            return False
        if length == 0.0 or t >= 1.0:
            return True
        t = min(1.0, t + room / length)


def split_block(i0: int, i1: int, j0: int, j1: int, k0: int, k1: int) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """A block of cells ``[i0, i1) x [j0, j1) x [k0, k1)`` cut in two halves across its longest side."""
    sizes = (i1 - i0, j1 - j0, k1 - k0)
    axis = sizes.index(max(sizes))
    bounds = [i0, i1, j0, j1, k0, k1]
    mid = (bounds[2 * axis] + bounds[2 * axis + 1]) // 2
    low, high = list(bounds), list(bounds)
    low[2 * axis + 1], high[2 * axis] = mid, mid
    return tuple(low), tuple(high)


class OccupancyGrid:
    """Free cells of a box at a resolution, padded by one blocked layer; cells are flat indices ``(k*NY + j)*NX + i``.

    Also the connected components of the free space (26-connected), so an unreachable goal is known at once.
    """

    def __init__(self, obstacles: ObstacleMap, lower: Point, upper: Point, resolution: float, margin: float,
                 bounds_margin: float = 0.0) -> None:
        self.lower, self.upper, self.resolution, self.margin = lower, upper, resolution, margin
        self.threshold = margin + resolution * SQRT3 / 2.0  # center clearance that keeps every step safe
        self.shape = tuple(max(1, int(math.floor((hi - lo) / resolution + 1e-9)))
                           for lo, hi in zip(lower, upper, strict=True))
        nx, ny, nz = self.shape
        self.NX, self.NY, self.NZ = nx + 2, ny + 2, nz + 2
        self.cells = bytearray(self.NX * self.NY * self.NZ)
        self.queries = 0
        self._obstacles = obstacles
        ranges = [self._inner_range(axis, bounds_margin) for axis in range(3)]
        if all(lo < hi for lo, hi in ranges):
            if callable(getattr(obstacles, "distances_to_obstacle", None)):
                self._classify_vectorized(*ranges[0], *ranges[1], *ranges[2])
            else:
                self._classify(*ranges[0], *ranges[1], *ranges[2])
        self._label()

    # -- geometry ----------------------------------------------------------------------------------
    def center(self, index: int) -> Point:
        k, rest = divmod(index, self.NX * self.NY)
        j, i = divmod(rest, self.NX)
        r, (x0, y0, z0) = self.resolution, self.lower
        return (x0 + (i - 0.5) * r, y0 + (j - 0.5) * r, z0 + (k - 0.5) * r)

    def index(self, point: Point) -> int | None:
        """The cell holding ``point`` (None outside the grid)."""
        ijk = []
        for lo, p, n in zip(self.lower, point, self.shape, strict=True):
            c = int(math.floor((p - lo) / self.resolution))
            if c == n and p - lo <= n * self.resolution + 1e-9:
                c = n - 1
            if not 0 <= c < n:
                return None
            ijk.append(c + 1)
        return (ijk[2] * self.NY + ijk[1]) * self.NX + ijk[0]

    def free(self, index: int) -> bool:
        return bool(self.cells[index])

    def _inner_range(self, axis: int, bounds_margin: float) -> tuple[int, int]:
        r, n = self.resolution, self.shape[axis]
        first = max(0, int(math.ceil((bounds_margin / r) - 0.5 - 1e-9)))  # centers at lower + (c + 0.5) r
        last = n - first
        return first + 1, last + 1

    # -- building ------------------------------------------------------------------------------------
    def _classify(self, i0: int, i1: int, j0: int, j1: int, k0: int, k1: int) -> None:
        """Mark free cells of block [i0,i1)x[j0,j1)x[k0,k1), splitting it until the distance decides (1-Lipschitz)."""
        r = self.resolution
        stack = [(i0, i1, j0, j1, k0, k1)]
        while stack:
            i0, i1, j0, j1, k0, k1 = stack.pop()
            x0, y0, z0 = self.lower
            center = (x0 + ((i0 + i1) / 2.0 - 1.0) * r, y0 + ((j0 + j1) / 2.0 - 1.0) * r,
                      z0 + ((k0 + k1) / 2.0 - 1.0) * r)
            reach = r / 2.0 * math.sqrt((i1 - i0 - 1) ** 2 + (j1 - j0 - 1) ** 2 + (k1 - k0 - 1) ** 2)
            d = self._obstacles.distance_to_obstacle(center)
            self.queries += 1
            if d - reach >= self.threshold:
                self._fill(i0, i1, j0, j1, k0, k1)
            elif d + reach < self.threshold:
                continue  # all blocked, as the grid starts
            else:
                stack.extend(split_block(i0, i1, j0, j1, k0, k1))

    def _classify_vectorized(self, i0: int, i1: int, j0: int, j1: int, k0: int, k1: int) -> None:
        """Mark free cells of block [i0,i1)x[j0,j1)x[k0,k1) from the distances of all their centers (numpy)."""
        import numpy as np

        r, (x0, y0, z0) = self.resolution, self.lower
        xs = x0 + (np.arange(i0, i1) - 0.5) * r
        ys = y0 + (np.arange(j0, j1) - 0.5) * r
        layer = np.empty(((j1 - j0) * (i1 - i0), 3))
        layer[:, 0] = np.tile(xs, j1 - j0)
        layer[:, 1] = np.repeat(ys, i1 - i0)
        cells = np.zeros((self.NZ, self.NY, self.NX), dtype=np.uint8)
        for k in range(k0, k1):  # a layer at a time: memory stays small on fine grids
            layer[:, 2] = z0 + (k - 0.5) * r
            free = self._obstacles.distances_to_obstacle(layer) >= self.threshold  # type: ignore[attr-defined]
            cells[k, j0:j1, i0:i1] = free.reshape(j1 - j0, i1 - i0)
            self.queries += len(layer)
        self.cells = bytearray(cells.tobytes())

    def _fill(self, i0: int, i1: int, j0: int, j1: int, k0: int, k1: int) -> None:
        ones = b"\x01" * (i1 - i0)
        for k in range(k0, k1):
            for j in range(j0, j1):
                base = (k * self.NY + j) * self.NX
                self.cells[base + i0:base + i1] = ones

    def _runs(self, j: int, k: int) -> list[tuple[int, int]]:
        base = (k * self.NY + j) * self.NX
        row, runs, pos = bytes(self.cells[base:base + self.NX]), [], 0
        while True:
            start = row.find(b"\x01", pos)
            if start < 0:
                return runs
            end = row.find(b"\x00", start)
            end = self.NX if end < 0 else end
            runs.append((start, end))
            pos = end

    def _label(self) -> None:
        """Connected components of the free cells, from runs along x merged with the 8 neighboring rows."""
        self._rows: dict[tuple[int, int], tuple[list[int], list[int], list[int]]] = {}
        parent: list[int] = []

        def find(a: int) -> int:
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        for k in range(1, self.NZ - 1):
            for j in range(1, self.NY - 1):
                runs = self._runs(j, k)
                if runs:
                    ids = list(range(len(parent), len(parent) + len(runs)))
                    parent.extend(ids)
                    self._rows[(j, k)] = ([s for s, _ in runs], [e for _, e in runs], ids)
        for (j, k), (starts, ends, ids) in self._rows.items():
            for dj, dk in ((1, -1), (1, 0), (1, 1), (0, 1)):
                other = self._rows.get((j + dj, k + dk))
                if other is None:
                    continue
                a = b = 0
                while a < len(starts) and b < len(other[0]):
                    if starts[a] <= other[1][b] and other[0][b] <= ends[a]:  # overlap, diagonals included
                        ra, rb = find(ids[a]), find(other[2][b])
                        if ra != rb:
                            parent[ra] = rb
                    if ends[a] < other[1][b]:
                        a += 1
                    else:
                        b += 1
        self._find = find

    def component(self, index: int) -> int | None:
        """The free-space component of a cell (None for a blocked one)."""
        if not self.cells[index]:
            return None
        k, rest = divmod(index, self.NX * self.NY)
        j, i = divmod(rest, self.NX)
        starts, _, ids = self._rows[(j, k)]
        return self._find(ids[bisect_right(starts, i) - 1])

    @property
    def free_count(self) -> int:
        return self.cells.count(1)


_GRIDS: OrderedDict[tuple, tuple[Any, OccupancyGrid]] = OrderedDict()
_GRID_CACHE_SIZE = 8
_GRIDS_LOCK = threading.Lock()  # grids are built on the planning worker and asked for on the engine loop


def occupancy_grid(obstacles: ObstacleMap, lower: Point, upper: Point, settings: PlannerSettings) -> OccupancyGrid:
    """The grid of ``obstacles`` in the box, built once per map, box, resolution and margins (an LRU of 8)."""
    resolution = settings.resolution
    volume = math.prod(max(hi - lo, resolution) for lo, hi in zip(lower, upper, strict=True))
    if volume / resolution ** 3 > settings.max_cells:
        resolution = (volume / settings.max_cells) ** (1.0 / 3.0)
        logger.warning("the planning box needs too many cells at %.2f m; planning at %.2f m",
                       settings.resolution, resolution)
    key = (id(obstacles), lower, upper, resolution, settings.margin, settings.bounds_margin)
    with _GRIDS_LOCK:
        cached = _GRIDS.get(key)
        if cached is not None and cached[0] is obstacles:
            _GRIDS.move_to_end(key)
            return cached[1]
    grid = OccupancyGrid(obstacles, lower, upper, resolution, settings.margin, settings.bounds_margin)
    with _GRIDS_LOCK:
        _GRIDS[key] = (obstacles, grid)  # the map is kept so its id cannot be reused while cached
        while len(_GRIDS) > _GRID_CACHE_SIZE:
            _GRIDS.popitem(last=False)
    return grid

