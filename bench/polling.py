"""A polling mission on the simulated clock: wall time per simulated minute, against a mission that waits.

Run ``python bench/polling.py``. Both missions stay on the ground for ``--seconds`` of simulated time: the
baseline waits (``api.wait``), the other polls ``trueBelief`` in a loop (each call lets the loop step after
``CALLS_PER_TICK`` calls). Prints each one's wall time and calls, and the polling/baseline ratio.
"""

from __future__ import annotations

import argparse
import time

import executive_engine_api as levant
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine import api
from aeroexec.engine.engine import Engine
from aeroexec.engine.missions.bridge import CALLS_PER_TICK


def timed(mission, seconds: float) -> float:
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    began = time.perf_counter()
    try:
        engine.run(mission, max_time=seconds)
    finally:
        engine.stop()
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="simulated seconds each mission runs")
    seconds = parser.parse_args().seconds
    calls = [0]

    def waiting() -> None:
        api.wait(seconds + 1)

    def polling() -> None:
        while not levant.trueBelief("visible(object_1)"):
            calls[0] += 1

    baseline = timed(waiting, seconds)
    polled = timed(polling, seconds)
    print(f"simulated time           {seconds:g} s (calls per engine step: {CALLS_PER_TICK})")
    print(f"waiting mission          {baseline:.3f} s wall")
    print(f"polling mission          {polled:.3f} s wall, {calls[0]} trueBelief calls "
          f"({calls[0] / seconds:.0f} per simulated second)")
    print(f"polling / waiting        {polled / baseline:.2f}x")


if __name__ == "__main__":
    main()
