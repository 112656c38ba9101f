"""A change of a running mission, checked and made on the engine's thread: its wall time against the engine's
period and against checking the mission file before flight (``aeroexec verify``'s check), measured in the same run.

Run ``python bench/mission_changes.py [--repeats N]``. For each mission (the field survey of missions/, 6.75 km; the
small survey), the flight is flown to its middle, then a waypoint is inserted after the running item: the time of
the change (plan, check of the new node, flight order and route of what is left, from the drone's position and
battery, and the change made) is the median of ``--repeats`` flights. Prints each time, the check of the whole file
before flight as the baseline, and their ratio, with the engine's period (50 ms) for scale.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

from aeroexec.engine.catalog import default_catalog
from aeroexec.flight import FlightSession, FlightSpec
from aeroexec.flight.missions import check_mission
from aeroexec.trees.mission_world import mission_world

MISSIONS = Path(__file__).parents[1] / "missions"
CASES = {"field_survey.plan": ("item 12 WAYPOINT", "after 14", "geo:47.39830,8.55900,120"),
         "survey.plan": ("item 9 WAYPOINT", "after 10", "geo:47.39777,8.54562,15")}


def one_change(mission: Path, running: str, where: str, point: str) -> float:
    with tempfile.TemporaryDirectory() as folder:
        session = FlightSession(FlightSpec(mission=mission, output=folder, register=False),
                                notify=lambda text: None, report=lambda problem: None).open()
        try:
            session.start_mission()
            engine = session.engine
            engine.run_until(lambda: any(n.name == running and n.status.name == "RUNNING"
                                         for _, n in session.tree.nodes), 3600)
            began = time.perf_counter()
            result = engine.supervisor.execute("insert", f"{where} 'GO_TO_POINT COORDINATES={point}'", "bench")
            spent = time.perf_counter() - began
            assert result.ok, result.message
            return spent
        finally:
            session.close()


def file_check(mission: Path) -> float:
    catalog, world = default_catalog(), mission_world(mission)
    began = time.perf_counter()
    check_mission(mission, catalog, world)
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="flights per mission (the median is shown)")
    repeats = parser.parse_args().repeats
    print(f"load average {os.getloadavg()[0]:.1f}; engine period 50 ms; median of {repeats}")
    for name, (running, where, point) in CASES.items():
        mission = MISSIONS / name
        change = statistics.median(one_change(mission, running, where, point) for _ in range(repeats))
        baseline = statistics.median(file_check(mission) for _ in range(repeats))
        print(f"{name:18} change {change * 1000:7.1f} ms ({change / 0.05:.2f} periods); file check "
              f"{baseline * 1000:7.1f} ms; change / file check {change / baseline:.2f}x")


if __name__ == "__main__":
    main()
