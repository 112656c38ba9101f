"""The flight journal's cost: the engine step with and without the journal (CPU of the whole process per step: every
thread counts, the journal's checkpoints and a Python mission's thread too; each run ends with what it recorded
committed), and the size of a 10-minute mission's journal.

Run ``python bench/journal.py`` (``--repeat N``, ``--quick`` for shorter runs). Three steps are measured: the bare
engine (``bench/engine.py``'s step), the engine as a flight runs it (its event log, events.jsonl, written; a tree's
.btlog too), and that flight with the journal. Each round runs the three in turn (the order rotated from round to
round, the garbage collected before each run), and the journal's cost is the median over the rounds of each
round's ratio, with its quartiles: what the machine's load does to a round does it to the three runs alike. The
load average is printed before and after. The process runs on one CPU (``--no-pin``: where the scheduler puts its
threads): a Python mission's thread and the engine's hand over to each other at every call, and whether the
scheduler keeps them on one core or wakes one on the other changes the step by up to 80 % from run to run (the
"slow mode" of earlier measures), which is the scheduler's doing, not the journal's.
Cases: a GO_TO_POINT patrol, a tree mission (a patrol with photos and broadcasts: node transitions and tree states
kept), a Python mission polling a belief between its behaviors (every call journaled). Target (issue 30): the
journal costs under 10 % of the step; a 10-minute mission's journal stays under a few MB.
"""

from __future__ import annotations

import argparse
import gc
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))

from engine import line, logging_quiet  # noqa: E402  (bench/engine.py, beside this script)

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
BARE, LOGGED, JOURNALED = "bare engine", "with events.jsonl", "with events.jsonl and the journal"


def engine(kind: str, folder: Path) -> Any:
    """An engine on the simulated drone, its battery lasting the bench (10 h of hover: the default 20 min would
    land the patrol, flown for an hour of engine time, half-way through)."""
    from aeroexec.drones.sim import SimulatedDrone, default_world
    from aeroexec.drones.sim.config import SimConfig
    from aeroexec.engine.engine import Engine
    from aeroexec.flight.flight_log import FlightLogWriter
    from aeroexec.flight.journal import JournalWriter

    world = default_world()
    folder.mkdir(parents=True, exist_ok=True)
    made = Engine(SimulatedDrone(world, config=SimConfig(battery_hover_minutes=600.0)), obstacles=world,
                  output_dir=folder)
    made.journal = JournalWriter(made, folder) if kind == JOURNALED else None
    if kind != BARE:
        FlightLogWriter(made, folder / "events.jsonl")
    if made.journal is not None:
        made.journal.went_live()
    return made


def stepper(made: Any, seconds: float, before: Callable[[], None] = lambda: None) -> Callable[[], int]:
    """Steps ``made`` for ``seconds`` of engine time (calling ``before`` first each step); what the journal recorded
    in the stretch is committed before it ends, so the stretch pays for it."""
    def run() -> int:
        steps, end = 0, made.now() + seconds
        while made.now() < end:
            before()
            made.step(made.period)
            steps += 1
        if made.journal is not None:
            made.journal.flush()
        return steps

    run.engine = made  # type: ignore[attr-defined]
    return run


def patrol_case(kind: str, folder: Path, seconds: float) -> Callable[[], int]:
    """``bench/engine.py``'s patrol, each leg asked for when the last one ends, as a mission asks (in that tick)."""
    made = engine(kind, folder)
    made.coordinator.activate("TAKE_OFF", {"ALTITUDE": 3.0}, source="mission")
    made.run_until(lambda: not made.coordinator.is_active("TAKE_OFF"), 30.0)
    leg = [0]

    def next_leg(*_: Any) -> None:
        leg[0] += 1
        made.coordinator.activate("GO_TO_POINT", {"COORDINATES": list(CORNERS[leg[0] % 4])}, source="mission",
                                  on_end=next_leg)

    next_leg()
    return stepper(made, seconds)


def tree_case(kind: str, folder: Path, seconds: float) -> Callable[[], int]:
    from aeroexec.trees import read_mission_tree
    from aeroexec.trees.groot.btlog import BtlogWriter
    from aeroexec.trees.runtime.runner import TreeMission

    made = engine(kind, folder)
    mission = TreeMission(read_mission_tree(PATROL.format(cycles=1000), "patrol.xml"), made)
    if kind != BARE:  # a flight keeps the tree's .btlog beside its events.jsonl
        BtlogWriter(mission, folder / "mission.btlog")
    if made.journal is not None:
        made.journal.attach_tree(mission)
    mission.start()
    return stepper(made, seconds)


def python_case(kind: str, folder: Path, seconds: float) -> Callable[[], int]:
    from aeroexec.engine.missions.replay import MissionRecorder
    from aeroexec.flight.missions import mission_function

    made = engine(kind, folder)
    path = folder / "polling.py"
    path.write_text(POLLING.format(corners=CORNERS * 100))
    if made.journal is not None:
        made.bridge.recorder = MissionRecorder(made.journal, made.now)
    made.start_mission(mission_function(path), "polling.py")
    return stepper(made, seconds)


def load() -> str:
    return "load average " + " / ".join(f"{value:.2f}" for value in os.getloadavg()) + " (1 / 5 / 15 min)"


def steps(repeat: int, seconds: float, pin: bool) -> None:
    print(f"Engine step with the journal (CPU of the process per step, every thread counted). {repeat} rounds of runs "
          f"of {seconds:g} s of engine time or more (the cheaper steps' runs longer: a few tenths of a second of CPU "
          f"each), the three in turn; medians over the rounds, [quartiles]")
    cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if pin and len(cpus) > 1:
        os.sched_setaffinity(0, {cpus[-1]})  # this thread, and every thread it starts from now on
    where = f"on CPU {cpus[-1]} of {len(cpus)}" if pin and len(cpus) > 1 else f"on {len(cpus) or 'all'} CPUs"
    print(f"  before: {load()}; the process {where}")
    cases = [("GO_TO_POINT patrol", patrol_case, 4), ("tree: patrol with photos and broadcasts", tree_case, 2),
             ("Python mission polling a belief", python_case, 1)]
    kinds = (BARE, LOGGED, JOURNALED)
    median = statistics.median
    with tempfile.TemporaryDirectory() as scratch:
        for name, case, longer in cases:
            runs = {kind: case(kind, Path(scratch) / f"{name[:4]}-{n}", seconds * longer)
                    for n, kind in enumerate(kinds)}
            for run in runs.values():  # warm up: imports, caches, the first behaviors
                run()
            per_step: dict[str, list[float]] = {kind: [] for kind in kinds}
            for round_ in range(repeat):
                for kind in kinds[round_ % 3:] + kinds[:round_ % 3]:
                    gc.collect()
                    began = time.process_time()
                    count = runs[kind]()
                    per_step[kind].append((time.process_time() - began) / count)
            rounds = list(zip(per_step[BARE], per_step[LOGGED], per_step[JOURNALED], strict=True))
            flight = [j / f - 1 for _, f, j in rounds]
            bare = [(j - f) / b for b, f, j in rounds]
            print(f"  {name} (runs of {seconds * longer * 20:.0f} steps)")
            line(f"  {BARE} / {LOGGED} / {JOURNALED}", " / ".join(f"{median(per_step[k]) * 1e6:.0f}" for k in kinds)
                 + " us")
            line("  the journal's cost, of a flight's step", f"+{median(flight):.1%}", quartiles(flight),
                 f"target <= 10 %: {'met' if median(flight) <= 0.10 else 'MISSED'}")
            line("  the journal's cost, of the bare engine's step", f"+{median(bare):.1%}", quartiles(bare))
    print(f"  after: {load()}")


def quartiles(values: list[float]) -> str:
    low, _, high = statistics.quantiles(values, n=4)
    return f"[{low:+.1%} {high:+.1%}]"


# -- the size ------------------------------------------------------------------------------------------------------
def size(minutes: float) -> None:
    from aeroexec.flight.session import FlightSession
    from aeroexec.flight.spec import FlightSpec

    print(f"The journal of a {minutes:g}-minute mission (a flight session: the journal beside events.jsonl)")
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        rounds = round(minutes * 60.0 / 14.5)  # a round of the patrol takes ~14.5 s
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
    parser.add_argument("--repeat", type=int, default=20, help="rounds of the three runs (default 20)")
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    parser.add_argument("--only", choices=["steps", "size"])
    parser.add_argument("--no-pin", action="store_true", help="let the scheduler place the threads (noisier)")
    options = parser.parse_args()
    logging_quiet()
    print(f"{'':52s}{'median':>22s}  {'quartiles':>16s}")
    if options.only in (None, "steps"):
        steps(options.repeat, 10.0 if options.quick else 30.0, not options.no_pin)
    if options.only in (None, "size"):
        size(2.0 if options.quick else 10.0)


if __name__ == "__main__":
    main()
