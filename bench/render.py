"""Simulated camera image speed on the default world: render time and PNG encoding time per frame, and the
occupancy map's scan time.

Run ``python bench/render.py`` (``--size 640x480`` for another image size, ``--frames 200`` for more frames).
The camera turns a full circle at several places of the world, so every obstacle, marker and object is drawn
from near and far; the mean and the worst frame are printed, for the render alone and with PNG encoding
(what ``SimulatedDrone.capture_image`` costs), then the time of one BUILD_MAP scan (``OccupancyMap.scan``).
"""

from __future__ import annotations

import argparse
import statistics
import time

from aeroexec.drones.sim import default_world
from aeroexec.drones.sim.camera import Camera
from aeroexec.drones.sim.render import SceneRenderer, to_png
from aeroexec.engine.planning.mapping import CameraModel, OccupancyMap
from aeroexec.engine.planning.path_planner import map_bounds

PLACES = [(0.0, 0.0, 2.0), (8.0, 0.0, 2.0), (-6.0, -8.0, 4.0), (4.0, 12.0, 1.5), (-15.0, 15.0, 8.0)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="320x240", help="WIDTHxHEIGHT of the image (320x240)")
    parser.add_argument("--frames", type=int, default=100, help="frames per measurement (100)")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.lower().split("x"))
    world = default_world()
    camera = Camera.from_settings(world.camera)

    start = time.perf_counter()
    renderer = SceneRenderer(world)
    build = time.perf_counter() - start

    poses = [(PLACES[i % len(PLACES)], (i * 37.0) % 360.0 - 180.0, i * 0.1) for i in range(args.frames)]
    render_times, png_times, sizes = [], [], []
    for position, yaw, t in poses:
        a = time.perf_counter()
        image = renderer.render(position, yaw, camera, t, width, height)
        b = time.perf_counter()
        png = to_png(image)
        c = time.perf_counter()
        render_times.append(b - a)
        png_times.append(c - a)
        sizes.append(len(png))

    lower, upper = map_bounds(world)
    occupancy = OccupancyMap(lower, upper, 0.5, world)
    model = CameraModel.of(world.camera)
    scan_times = []
    for position, yaw, _ in poses[:50]:
        a = time.perf_counter()
        occupancy.scan(position, yaw, model)
        scan_times.append(time.perf_counter() - a)

    def ms(values: list[float]) -> str:
        return f"mean {statistics.fmean(values) * 1000:6.2f} ms, worst {max(values) * 1000:6.2f} ms"

    print(f"default world, {width}x{height}, {args.frames} frames")
    print(f"  scene build (once per world)   {build * 1000:6.2f} ms")
    print(f"  render                         {ms(render_times)}")
    print(f"  render + PNG (capture_image)   {ms(png_times)}  ({statistics.fmean(sizes) / 1024:.0f} KiB per frame)")
    print(f"  map scan ({model.columns}x{model.rows} rays, 0.5 m) {ms(scan_times)}")


if __name__ == "__main__":
    main()
