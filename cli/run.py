"""``aeroexec run MISSION``: check a mission (Python, or a behavior tree in XML or YAML), then fly it on the
built-in simulator or a MAVSDK drone.

The events are printed as they happen. A mission that fails the static check
never flies. When the mission ends (or the operator presses Ctrl-C) with the
drone in the air, the drone lands before the command returns.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from aeroexec.cli.catalog import chosen_catalog
from aeroexec.cli.live import OperatorConsole
from aeroexec.cli.live import wanted as live_view_wanted
from aeroexec.cli.mission_files import MissionFileError, check_mission, is_plan, mission_function, world_home
from aeroexec.drones import Drone
from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.clock import SimulatedClock, WallClock
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.engine.supervision.flight_log import FlightLogWriter
from aeroexec.engine.supervision.output import make_output_folder
from aeroexec.engine.supervision.supervisor import land_if_flying
from aeroexec.trees import TreeDocument
from aeroexec.trees.btlog import BtlogWriter
from aeroexec.trees.runner import TreeMission

logger = logging.getLogger(__name__)


class RunError(Exception):
    """A problem that stops ``aeroexec run`` before flight, already phrased for the operator."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("mission", help="a Python mission file with a mission() or runMission() function, a "
                                        "behavior tree (.xml, .yaml) or a QGroundControl plan (.plan)")
    add_flight_arguments(parser)


def add_flight_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every way of flying a mission shares (run, and the behavior-tree runner)."""
    parser.add_argument("--drone", default="sim", metavar="sim|mavsdk:URL",
                        help="the built-in simulated drone (default) or a MAVSDK vehicle, "
                             "e.g. mavsdk:udpin://0.0.0.0:14540")
    parser.add_argument("--world", metavar="FILE", help="the simulated world (default: the built-in one)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("--speed", type=float, metavar="N",
                        help="simulated time N times faster than real time (default: as fast as possible)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the simulated sensors")
    parser.add_argument("--max-time", type=float, default=1800.0, metavar="S",
                        help="stop the mission after S seconds of mission time (default 1800)")
    parser.add_argument("--log", metavar="FILE",
                        help="write the event log (one JSON object per line) to FILE (default: events.jsonl "
                             "in the output folder)")
    parser.add_argument("--quiet", action="store_true", help="print only the outcome")
    parser.add_argument("--plain", action="store_true",
                        help="one line per event instead of the live view (always so when stdout is no terminal)")
    parser.add_argument("--output", metavar="DIR",
                        help="where the event log, photos, videos and maps go (default: "
                             "aeroexec_output/<date-time>)")
    parser.add_argument("--answers", metavar="FILE",
                        help="answer the mission's questions from FILE (YAML: question -> answer, or a list); "
                             "default: ask at the terminal when interactive, else the first possible answer")


def run(args: argparse.Namespace) -> int:
    path = Path(args.mission)
    try:
        catalog = chosen_catalog(args.catalog)
        mission = load_mission(path, catalog, world_home(args.world) if is_plan(path) else None)
        return fly(args, catalog, mission, path.name)
    except (RunError, MissionFileError) as error:
        print(error, file=sys.stderr)
        return 1


def load_mission(path: Path, catalog: BehaviorCatalog, home: Any = None) -> Callable[[], Any] | TreeDocument:
    """Check a mission before flight (printing every problem); the Python function or the tree to fly."""
    checked = check_mission(path, catalog, home)
    for problem in checked.problems:
        print(problem, file=sys.stderr)
    if checked.errors:
        count = len(checked.errors)
        raise RunError(f"{path}: {count} error{'s' if count != 1 else ''}; the mission will not fly")
    return checked.tree if checked.tree is not None else mission_function(path)


def make_drone(args: argparse.Namespace) -> tuple[Drone, Any, bool]:
    """The drone, the world it flies in (obstacles for the planner), and whether it runs on simulated time."""
    from aeroexec.drones.sim import WorldError, default_world, load_world

    try:
        world = load_world(args.world) if args.world else default_world()
    except WorldError as error:
        raise RunError(str(error)) from None
    if args.drone == "sim":
        from aeroexec.drones.sim import SimulatedDrone

        return SimulatedDrone(world, seed=args.seed), world, True
    if args.drone.startswith("mavsdk:"):
        from aeroexec.drones.mavsdk import MavsdkDrone

        url = args.drone[len("mavsdk:"):]
        try:
            drone = MavsdkDrone(url)
        except ValueError as error:
            raise RunError(f"--drone {args.drone}: {error}") from None
        print(f"connecting to {url} ...", file=sys.stderr)
        if not drone.wait_ready(60.0):
            why = "; ".join(drone.not_ready_because()) or "no answer"
            drone.close()
            raise RunError(f"--drone {args.drone}: the vehicle is not ready to fly after 60 s ({why})")
        return drone, world if args.world else None, False
    raise RunError(f"--drone {args.drone}: expected sim or mavsdk:URL (e.g. mavsdk:udpin://0.0.0.0:14540)")


def fly(args: argparse.Namespace, catalog: BehaviorCatalog, mission: Callable[[], Any] | TreeDocument,
        name: str) -> int:
    live = live_view_wanted(args)  # the live view paces the simulator to real time unless --speed says
    operator = make_operator(args, live)
    drone, world, simulated = make_drone(args)
    clock = SimulatedClock(speed=args.speed or (1.0 if live else None)) if simulated else WallClock()
    folder = make_output_folder(getattr(args, "output", None))
    engine = Engine(drone, catalog=catalog, clock=clock, obstacles=world, operator=operator, output_dir=folder)
    log_path = Path(args.log) if args.log else folder / "events.jsonl"
    try:
        flight_log = FlightLogWriter(engine, log_path, meta={"mission": name, "world": _absolute(args.world),
                                                             "drone": args.drone, "seed": args.seed,
                                                             "output": str(folder)})
    except OSError as error:
        engine.stop()
        operator.close()
        drone.close()
        raise RunError(f"the event log {log_path} cannot be written: {error}") from None
    print(f"event log: {log_path}", file=sys.stderr)
    if not live:
        engine.log.subscribe(printer(None if args.quiet else sys.stdout))
    console = OperatorConsole(engine, folder, name, mission, live).start()  # control socket, live view, keys
    btlog = None
    try:
        try:
            if isinstance(mission, TreeDocument):
                tree_mission = TreeMission(mission, engine, name=name)
                btlog = BtlogWriter(tree_mission, folder / "mission.btlog", catalog)
                tree_mission.run(max_time=args.max_time)
            else:
                engine.run(mission, max_time=args.max_time, name=name)
        except KeyboardInterrupt:
            print("interrupted by the operator: aborting and landing (Ctrl-C again leaves the drone as it is)",
                  file=sys.stderr)
            engine.log.record("operator_interrupt", detail="Ctrl-C")
            engine.supervisor.execute("abort", "Ctrl-C: aborted by the operator", origin="keyboard")
        land_if_flying(engine)
    except KeyboardInterrupt:
        print("interrupted again: leaving the drone as it is", file=sys.stderr)
    finally:
        console.close()
        engine.stop()
        flight_log.close()
        if btlog is not None:
            btlog.close()
        operator.close()
        drone.close()
    return summary(engine, name)


def make_operator(args: argparse.Namespace, live: bool = False) -> Any:
    """The operator channel: --answers FILE, else the live view's (questions wait for t or ``aeroexec ctl
    answer``), else the terminal when interactive, else logged default answers."""
    from aeroexec.engine.supervision.operator import OperatorError, RemoteOperator
    from aeroexec.engine.supervision.operator import make_operator as operator_for

    if live and getattr(args, "answers", None) is None:
        return RemoteOperator()
    try:
        return operator_for(getattr(args, "answers", None), interactive=sys.stdin is not None and sys.stdin.isatty())
    except OperatorError as error:
        raise RunError(f"--answers {error}") from None


def summary(engine: Engine, name: str) -> int:
    failed = engine.log.events(kind="mission_failed")
    completed = engine.log.events(kind="mission_completed")
    outcomes = [e for e in engine.log.events() if e.kind in {o.value for o in Outcome}]
    print(f"{name}: {'completed' if completed and not failed else 'failed' if failed else 'stopped'} at "
          f"t={engine.now():.1f} s; {len(outcomes)} behavior events, "
          f"{sum(e.kind == 'GOAL_ACHIEVED' for e in outcomes)} goals achieved", file=sys.stderr)
    return 0 if completed and not failed else 1


def _absolute(path: str | None) -> str | None:
    return str(Path(path).resolve()) if path else None


def printer(out: TextIO | None) -> Callable[[EngineEvent], None]:
    def show(event: EngineEvent) -> None:
        if out is not None:
            print(_shown(event), file=out, flush=True)

    return show


def _shown(event: EngineEvent) -> str:
    """An event as a line; a tree node's status change is indented at the node's depth in the tree."""
    if event.kind != "node_status":
        return str(event)
    data = event.data
    return f"[{event.time:8.2f}] tree {'  ' * int(data.get('depth', 0))}{data.get('node')}: " \
           f"{data.get('old')} -> {data.get('new')}"
