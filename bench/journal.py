"""The flight journal's cost: the engine step with and without the journal (CPU of the whole process per step: the
journal's own thread counts), measured alternately in one run, and the size of a 10-minute mission's journal.

Run ``python bench/journal.py`` (``--repeat N``, ``--quick`` for shorter runs). Cases: a GO_TO_POINT patrol (the
step ``bench/engine.py`` measures), a QGroundControl survey (a tree mission: node transitions and tree states
kept), a Python mission polling a belief between its behaviors (every call journaled). Target (issue 30): the
journal costs under 10 % of the step; a 10-minute mission's journal stays under a few MB.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))

from engine import line, logging_quiet, spread  # noqa: E402  (bench/engine.py, beside this script)

CORNERS = [(0.0, -12.0, 3.0), (15.0, -12.0, 3.0), (15.0, -17.0, 3.0), (0.0, -17.0, 3.0)]
PATROL = f"""<root BTCPP_format="4" main_tree_to_execute="Patrol"><BehaviorTree ID="Patrol"><Sequence>
  <TAKE_OFF ALTITUDE="3"/>
  <Repeat num_cycles="{{cycles}}"><Sequence>
    {"".join(f'<GO_TO_POINT COORDINATES="{x:g}, {y:g}, {z:g}"/><TAKE_PHOTO/>' for x, y, z in CORNERS)}
    <BROADCAST_MESSAGE MESSAGE="round done"/>
  </Sequence></Repeat>
  <LAND/>
</Sequence></BehaviorTree></root>"""
POLLING = """import aeroexec.engine.api as api

def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    for corner in {corners}:
        api.activate_behavior("GO_TO_POINT", coordinates=corner)
        while api.is_active_behavior("GO_TO_POINT"):
            api.true_belief("charge(battery, ?C), ?C > 20")
        api.execute_behavior("TAKE_PHOTO")
    api.execute_behavior("LAND")
"""


# -- the step ------------------------------------------------------------------------------------------------------
def engine(journaled: bool, folder: Path) -> Any:
    from aeroexec.drones.sim import SimulatedDrone, default_world
    from aeroexec.engine.engine import Engine
    from aeroexec.flight.journal import JournalWriter

    world = default_world()
    folder.mkdir(parents=True, exist_ok=True)
    made = Engine(SimulatedDrone(world), obstacles=world, output_dir=folder)
    made.journal = JournalWriter(made, folder) if journaled else None
    if made.journal is not None:
        made.journal.went_live()
    return made


def patrol_case(journaled: bool, folder: Path, seconds: float) -> Callable[[], int]:
    made = engine(journaled, folder)
    made.coordinator.activate("TAKE_OFF", {"ALTITUDE": 3.0}, source="mission")
    made.run_until(lambda: not made.coordinator.is_active("TAKE_OFF"), 30.0)
    leg = [0]

    def run() -> int:
        steps, end = 0, made.now() + seconds
        while made.now() < end:
            if not made.coordinator.is_active("GO_TO_POINT"):
                made.coordinator.activate("GO_TO_POINT", {"COORDINATES": list(CORNERS[leg[0] % 4])}, source="mission")
                leg[0] += 1
            made.step(made.period)
            steps += 1
        return steps

    return run


def tree_case(journaled: bool, folder: Path, seconds: float) -> Callable[[], int]:
    from aeroexec.trees import read_mission_tree
    from aeroexec.trees.runtime.runner import TreeMission

    made = engine(journaled, folder)
    mission = TreeMission(read_mission_tree(PATROL.format(cycles=1000), "patrol.xml"), made)
    if made.journal is not None:
        made.journal.attach_tree(mission)
    mission.start()

    def run() -> int:
        steps, end = 0, made.now() + seconds
        while made.now() < end:
            made.step(made.period)
            steps += 1
        return steps

    return run


def python_case(journaled: bool, folder: Path, seconds: float) -> Callable[[], int]:
    from aeroexec.engine.missions.replay import MissionRecorder
    from aeroexec.flight.missions import mission_function

    made = engine(journaled, folder)
    path = folder / "polling.py"
    path.write_text(POLLING.format(corners=CORNERS * 100))
    if made.journal is not None:
        made.bridge.recorder = MissionRecorder(made.journal, made.now)
    made.start_mission(mission_function(path), "polling.py")

    def run() -> int:
        steps, end = 0, made.now() + seconds
        while made.now() < end:
            made.step(made.period)
            steps += 1
        return steps

    return run


def steps(repeat: int, seconds: float) -> None:
    print(f"Engine step with the journal (CPU of the process per step, both measured alternately, {seconds:g} s of "
          f"engine time each; ratio with / without)")
    cases = [("GO_TO_POINT patrol", patrol_case), ("tree: patrol with photos and broadcasts", tree_case),
             ("Python mission polling a belief", python_case)]
    with tempfile.TemporaryDirectory() as scratch:
        for name, case in cases:
            runs = {flag: case(flag, Path(scratch) / f"{name[:4]}-{flag}", seconds) for flag in (False, True)}
            for run in runs.values():  # warm up: imports, caches, the first behaviors
                run()
            times: dict[bool, list[float]] = {False: [], True: []}
            for _ in range(repeat):
                for flag, run in runs.items():
                    began = time.process_time()
                    count = run()
                    times[flag].append((time.process_time() - began) / count)
            base, journal = spread(times[False]), spread(times[True])
            ratio = journal[1] / base[1]
            line(f"{name}: without / with", f"{base[1] * 1e6:.0f} / {journal[1] * 1e6:.0f} us",
                 f"{ratio:.3f}x", f"target <= 1.10: {'met' if ratio <= 1.10 else 'MISSED'}")


# -- the size ------------------------------------------------------------------------------------------------------
def size(minutes: float) -> None:
    from aeroexec.flight.session import FlightSession
    from aeroexec.flight.spec import FlightSpec

    print(f"The journal of a {minutes:g}-minute mission (a flight session: the journal beside events.jsonl)")
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        rounds = round(minutes * 60.0 / 18.0)  # a round of the patrol takes ~18 s
        for name, text in (("patrol.xml", PATROL.format(cycles=rounds)),
                           ("polling.py", POLLING.format(corners=CORNERS * rounds))):
            mission = folder / name
            mission.write_text(text)
            output = folder / f"out-{name}"
            spec = FlightSpec(mission=mission, output=str(output), register=False, max_time=minutes * 90.0)
            with FlightSession(spec, notify=lambda text: None) as session:
                outcome = session.fly()
            journal = (output / "journal.sqlite").stat().st_size
            log = (output / "events.jsonl").stat().st_size
            line(f"{name}: {outcome.status.word} at t={session.engine.now():.0f} s", f"{journal / 1e6:.2f} MB",
                 f"events.jsonl {log / 1e6:.2f} MB", f"target: a few MB: {'met' if journal < 3e6 else 'MISSED'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    parser.add_argument("--only", choices=["steps", "size"])
    options = parser.parse_args()
    logging_quiet()
    print(f"{'':52s}{'median':>22s}  {'ratio':>16s}")
    if options.only in (None, "steps"):
        steps(options.repeat, 5.0 if options.quick else 20.0)
    if options.only in (None, "size"):
        size(2.0 if options.quick else 10.0)


if __name__ == "__main__":
    main()
