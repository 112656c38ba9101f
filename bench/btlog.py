"""The cost of a tree mission's Groot2 replay file: missions/survey.plan flown on the simulator with and without
the .btlog writer (which follows BehaviorTree.CPP's transitions tick by tick), as a ratio measured in one run.

Run ``python bench/btlog.py`` (``--runs 5``). It prints the wall time of each kind of run (best of the runs,
alternating, after a warm-up flight), the ratio with/without, the ticks and transitions written and the file's size.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.trees.groot.btlog import BtlogWriter
from aeroexec.trees.mission_file import load_mission_tree
from aeroexec.trees.runtime.runner import TreeMission

SURVEY = Path(__file__).parents[1] / "missions" / "survey.plan"


def fly(with_btlog: bool, folder: Path) -> tuple[float, int, int]:
    """Wall seconds of one flight, its ticks and the transitions written."""
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, output_dir=folder)
    try:
        mission = TreeMission(load_mission_tree(SURVEY, world.home), engine)
        ticks = [0]
        mission.observers.append(lambda visited: ticks.__setitem__(0, ticks[0] + 1))
        writer = BtlogWriter(mission, folder / "survey.btlog", engine.catalog) if with_btlog else None
        start = time.perf_counter()
        mission.run(600.0)
        elapsed = time.perf_counter() - start
        if writer is not None:
            writer.close()
        return elapsed, ticks[0], writer.transitions if writer else 0
    finally:
        engine.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        fly(False, folder)  # warm-up: imports, the catalog, the planner's grid
        plain, results = [], []
        for _ in range(args.runs):  # alternating, so both kinds share the machine's state
            plain.append(fly(False, folder)[0])
            results.append(fly(True, folder))
        without, with_log = min(plain), min(r[0] for r in results)
        _, ticks, transitions = results[0]
        size = (folder / "survey.btlog").stat().st_size
    print(f"survey.plan on the simulator, best of {args.runs}: without .btlog {without:.3f} s, "
          f"with {with_log:.3f} s, ratio {with_log / without:.3f}")
    print(f"{ticks} ticks, {transitions} transitions written, {size} bytes")


if __name__ == "__main__":
    main()
