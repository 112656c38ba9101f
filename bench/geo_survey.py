"""A 1 km x 500 m survey at a real home (missions/field_survey.plan): verified (world generated around it, transects
computed, route and battery estimated) and flown on the simulated clock; simulated seconds per CPU second, against
the 40 m survey of missions/survey.plan flown in the same run as the baseline.

    python bench/geo_survey.py [--runs N]

The target is 100 simulated seconds per CPU second (100x real time) for the big survey; the ratio to the baseline
says whether flying at real scale costs more per simulated second than flying in the demo field.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.engine import Engine
from aeroexec.flight.missions import check_mission
from aeroexec.trees.mission_world import mission_world
from aeroexec.trees.runtime.runner import TreeMission

MISSIONS = Path(__file__).parents[1] / "missions"
FIELD, BASELINE = MISSIONS / "field_survey.plan", MISSIONS / "survey.plan"


def verify(path: Path) -> tuple[float, object, object]:
    """CPU seconds to choose the world and check the mission (route included); the world and the check."""
    start = time.process_time()
    world = mission_world(path)
    checked = check_mission(path, default_catalog(), world)
    return time.process_time() - start, world, checked


def fly(path: Path, folder: Path) -> tuple[float, float, int]:
    """(simulated seconds, CPU seconds, photos) of one flight of ``path`` in its world."""
    _, world, checked = verify(path)
    assert not checked.errors, [str(p) for p in checked.errors]
    engine = Engine(SimulatedDrone(world), obstacles=world, output_dir=folder)
    try:
        mission = TreeMission(checked.tree, engine)
        start = time.process_time()
        status = mission.run(3600.0)
        cpu = time.process_time() - start
        assert status.name == "SUCCESS", status
        return engine.now(), cpu, len(list(folder.glob("photo_*.png")))
    finally:
        engine.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1, help="flights of each mission (the best is kept)")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} at the start")
    verify(FIELD)  # warm-up: imports, the catalog, pymap3d
    cpu, _, checked = verify(FIELD)
    print(f"verify {FIELD.name}: {cpu * 1000:.0f} ms CPU; {checked.route.summary()}")
    best: dict[Path, tuple[float, float, int]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for run in range(args.runs):  # alternating, so both share the machine's state
            for path in (BASELINE, FIELD):
                folder = Path(tmp) / f"{path.stem}_{run}"
                flown = fly(path, folder)
                if path not in best or flown[1] < best[path][1]:
                    best[path] = flown
    for path, (simulated, cpu, photos) in best.items():
        print(f"{path.name}: {simulated:.0f} s simulated in {cpu:.2f} s CPU: {simulated / cpu:.0f}x real time, "
              f"{photos} photos")
    field, base = best[FIELD], best[BASELINE]
    ratio = (field[0] / field[1]) / (base[0] / base[1])
    print(f"speed at real scale against the demo field's: {ratio:.2f} (target: the field survey >= 100x real time: "
          f"{'met' if field[0] / field[1] >= 100 else 'NOT met'})")
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
