"""Path planner speed on the default world: occupancy grid build time and plan time for a few queries.

Run ``python bench/planning.py`` (``--resolution 0.25`` or ``--margin 1.5`` to change the grid). The grid is
built cold (cache cleared) and then taken from the cache; each query is planned ``--repeat`` times on the cached
grid and the best time is printed with the waypoints, the A* expansions and the path length.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

from aeroexec.drones.sim import default_world
from aeroexec.drones.sim.shapes import Box
from aeroexec.engine.planning import grid as grids
from aeroexec.engine.planning import path_planner as planning
from aeroexec.engine.planning.exploration import ExplorationPlanner, ExplorationSettings

QUERIES = [
    ("home -> behind the tower", (0.0, 0.0, 2.0), (12.0, 12.0, 2.0)),
    ("from the ground, behind the tower", (0.0, 0.0, 0.0), (12.0, 12.0, 3.0)),
    ("home -> behind the wall", (0.0, 0.0, 2.0), (-6.0, 9.0, 2.0)),
    ("corner -> corner", (-18.0, -18.0, 1.0), (18.0, 18.0, 1.0)),
    ("home -> by the shed", (0.0, 0.0, 2.0), (-12.0, 17.5, 1.0)),
    ("open line", (0.0, 0.0, 2.0), (-3.0, -12.0, 4.0)),
    ("inside the tower (no path)", (0.0, 0.0, 2.0), (8.0, 8.0, 5.0)),
]


def length(start: tuple[float, float, float], path: list[tuple[float, float, float]]) -> float:
    points = [start, *path]
    return sum(math.dist(a, b) for a, b in zip(points, points[1:], strict=False))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=float, default=0.5)
    parser.add_argument("--margin", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=5)
    options = parser.parse_args()
    world = default_world()
    settings = planning.PlannerSettings(resolution=options.resolution, margin=options.margin)
    planner = planning.PathPlanner(world, settings)

    grids._GRIDS.clear()
    began = time.perf_counter()
    grid = planner.grid()
    built = time.perf_counter() - began
    began = time.perf_counter()
    planner.grid()
    cached = time.perf_counter() - began
    nx, ny, nz = grid.shape
    print(f"grid {nx} x {ny} x {nz} = {nx * ny * nz} cells at {grid.resolution:g} m, margin {settings.margin:g} m: "
          f"built in {built * 1000:.1f} ms ({grid.queries} distance queries, {grid.free_count} free cells), "
          f"cached {cached * 1e6:.0f} us")
    for name, start, goal in QUERIES:
        best, path = math.inf, []
        for _ in range(options.repeat):
            began = time.perf_counter()
            path = planner.plan(start, goal)
            best = min(best, time.perf_counter() - began)
        summary = (f"{len(path)} waypoints, {length(start, path):.1f} m (straight {math.dist(start, goal):.1f} m)"
                   if path else f"no path: {planner.reason}")
        print(f"{name:36s} {best * 1000:7.1f} ms  {planner.expanded:6d} expanded  {summary}")

    walls = [Box(f"shell{n}", c, size) for n, (c, size) in enumerate([
        ((0.0, -15.0, 0.25), (6.0, 6.0, 0.5)), ((0.0, -15.0, 5.75), (6.0, 6.0, 0.5)),
        ((-2.75, -15.0, 3.0), (0.5, 6.0, 6.0)), ((2.75, -15.0, 3.0), (0.5, 6.0, 6.0)),
        ((0.0, -17.75, 3.0), (6.0, 0.5, 6.0)), ((0.0, -12.25, 3.0), (6.0, 0.5, 6.0))])]
    shelled = dataclasses.replace(world, obstacles=world.obstacles + tuple(walls))
    enclosed = planning.PathPlanner(shelled, settings)
    began = time.perf_counter()
    path = enclosed.plan((0.0, 0.0, 2.0), (0.0, -15.0, 3.0))
    print(f"{'enclosed goal, cold grids':36s} {(time.perf_counter() - began) * 1000:7.1f} ms  "
          f"{'no path: ' + enclosed.reason if not path else 'a path?!'} (both resolutions built)")

    region = [(-20.0, -20.0, 3.0), (20.0, -20.0, 3.0), (20.0, 20.0, 3.0), (-20.0, 20.0, 3.0)]
    began = time.perf_counter()
    explorer = ExplorationPlanner(region, ExplorationSettings(), world)
    count, position = 0, (0.0, 0.0, 0.0)
    while (point := explorer.next_point(position)) is not None:
        count, position = count + 1, point
    print(f"exploration of the whole field at 3 m: {count} points handed out in "
          f"{(time.perf_counter() - began) * 1000:.1f} ms")


if __name__ == "__main__":
    main()
