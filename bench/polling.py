"""A polling mission on the simulated clock: wall time per simulated minute, against a mission that waits.

Run ``python bench/polling.py``. The missions stay on the ground for ``--seconds`` of simulated time: the
baseline waits (``api.wait``), one polls ``trueBelief`` in a loop (each call lets the loop step after
``CALLS_PER_TICK`` calls), one asks again and again for a behavior that is refused (GO_TO_POINT on the ground,
as Aerostack's wiki missions do after a low-battery landing: each refusal lets the loop step). Prints each one's
wall and CPU time and calls, and the ratios to the baseline.
"""

from __future__ import annotations

import argparse
import time

from aeroexec.dialects.aerostack import executive_engine_api as levant
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine import api
from aeroexec.engine.engine import Engine
from aeroexec.engine.missions.bridge import CALLS_PER_TICK


def timed(mission, seconds: float) -> tuple[float, float]:
    """Wall and CPU seconds to fly ``mission`` for ``seconds`` of simulated time."""
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    began, cpu = time.perf_counter(), time.process_time()
    try:
        engine.run(mission, max_time=seconds)
    finally:
        engine.stop()
    return time.perf_counter() - began, time.process_time() - cpu


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

    def refused() -> None:
        while levant.executeBehavior("GO_TO_POINT", coordinates=[4, -4, 3]) != "GOAL_ACHIEVED":
            calls[1] += 1

    calls.append(0)
    baseline = timed(waiting, seconds)
    polled = timed(polling, seconds)
    asked = timed(refused, seconds)
    print(f"simulated time           {seconds:g} s (calls per engine step: {CALLS_PER_TICK})")
    print(f"waiting mission          {baseline[0]:.3f} s wall, {baseline[1]:.3f} s CPU")
    print(f"polling mission          {polled[0]:.3f} s wall, {polled[1]:.3f} s CPU, {calls[0]} trueBelief calls "
          f"({calls[0] / seconds:.0f} per simulated second)")
    print(f"refused-request mission  {asked[0]:.3f} s wall, {asked[1]:.3f} s CPU, {calls[1]} refused requests "
          f"({calls[1] / seconds:.0f} per simulated second)")
    print(f"polling / waiting        {polled[0] / baseline[0]:.2f}x wall")
    print(f"refused / waiting        {asked[0] / baseline[0]:.2f}x wall, {asked[1] / baseline[1]:.2f}x CPU")


if __name__ == "__main__":
    main()
