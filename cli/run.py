"""``aeroexec run MISSION``: check a mission (Python, or a behavior tree in XML or YAML), then fly it on the
built-in simulator or a MAVSDK drone.

The events are printed as they happen. A mission that fails the static check
never flies. When the mission ends (or the operator presses Ctrl-C) with the
drone in the air, the drone lands before the command returns; if its link is
down, the engine keeps trying to reach it for ``--link-grace`` seconds first.
A run whose link was lost, whose landing failed, or that leaves the drone armed
or in the air ends non-zero, its last line saying why.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from aeroexec.cli.flying import robots, web
from aeroexec.cli.flying.lines import whole_lines
from aeroexec.cli.flying.mission_files import MissionFileError, check_mission, mission_function
from aeroexec.cli.verify import WorldChoiceError, add_library_arguments, chosen_world
from aeroexec.cli.views.live import OperatorConsole
from aeroexec.cli.views.live import wanted as live_view_wanted
from aeroexec.drones import Drone
from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.clock import SimulatedClock, WallClock
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.engine.library import LibraryError, default_library, default_processes, default_updaters
from aeroexec.engine.library import make_drone as make_adapter_drone
from aeroexec.engine.supervision.flight_end import LINK_GRACE, end_flight
from aeroexec.engine.supervision.flight_log import FlightLogWriter
from aeroexec.engine.supervision.output import make_output_folder
from aeroexec.engine.supervision.run_status import COMPLETED, FAILED, RunStatus, record_run_status, run_status
from aeroexec.trees import TreeDocument
from aeroexec.trees.btlog import BtlogWriter
from aeroexec.trees.runtime.runner import TreeMission

logger = logging.getLogger(__name__)

READY_TIMEOUT = 180.0  # s a MAVSDK vehicle may take to be ready (ArduCopter SITL: ~45 s from boot)


class RunError(Exception):
    """A problem that stops ``aeroexec run`` before flight, already phrased for the operator."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("mission", help="the mission: a Python program with a mission() or runMission() function "
                                         "(.py), a behavior tree (BehaviorTree.CPP XML .xml, or YAML .yaml/.yml), "
                                         "a TML mission (.tml.xml) or a QGroundControl plan (.plan)")
    parser.epilog = ("exit status: 0 completed, 3 completed with refused requests, 1 failed, 4 aborted "
                     "(the words the summary line, the live view and the event log's run_ended use)")
    add_flight_arguments(parser)
    fleet = parser.add_argument_group("fleet (over Zenoh)")
    fleet.add_argument("--fleet", metavar="NAME", help="join the fleet NAME (simulated time then runs at real time "
                                                       "unless --speed says)")
    fleet.add_argument("--name", metavar="D", help="this drone's name in the fleet (with --fleet)")
    fleet.add_argument("--connect", action="append", metavar="ENDPOINT",
                       help="the fleet's router (default tls/127.0.0.1:7447)")
    fleet.add_argument("--credentials", metavar="DIR|CERT",
                       help="this drone's identity: a folder holding D.pem, D.key and the fleet's ca.pem, or the "
                            "certificate file (its .key and ca.pem beside it); see aeroexec fleet --make-credentials")
    fleet.add_argument("--share", action="append", default=[], metavar="PREDICATE",
                       help="share this drone's beliefs of PREDICATE with the fleet (repeatable)")
    fleet.add_argument("--token", metavar="T", help="the fleet's token for operator commands (default: "
                                                    "$AEROEXEC_FLEET_TOKEN, else a new one in fleet.json)")


def add_flight_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every way of flying a mission shares (run, and the behavior-tree runner)."""
    robots.add_arguments(parser)
    parser.add_argument("--drone", default="sim", metavar="sim|mavsdk:URL|NAME:ADDRESS",
                        help="the built-in simulated drone (default), a MAVSDK vehicle "
                             "(e.g. mavsdk:udpin://0.0.0.0:14540), or an installed adapter (aeroexec.drones "
                             "entry point NAME)")
    parser.add_argument("--ready-timeout", type=_seconds, default=READY_TIMEOUT, metavar="S",
                        help=f"how long a MAVSDK vehicle may take to be ready to fly: connected, armable, with "
                             f"global and home positions (default {READY_TIMEOUT:g} s)")
    parser.add_argument("--link-grace", type=_seconds, default=LINK_GRACE, metavar="S",
                        help=f"when the link to the drone is down at the end of the mission, keep trying to reach it "
                             f"this long to land it (default {LINK_GRACE:g} s; its own failsafe acts meanwhile)")
    parser.add_argument("--world", metavar="FILE", help="the simulated world; literal destinations are checked "
                                                        "against it (default: the robot kind's, else the "
                                                        "built-in one)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("--speed", type=float, metavar="N",
                        help="simulated time N times faster than real time (default: real time with the live "
                             "view in a terminal; as fast as possible with --plain, --quiet or no terminal)")
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
    add_library_arguments(parser)
    parser.add_argument("--updater", action="append", default=[], metavar="MODULE:ATTR",
                        help="belief updaters to add: a callable (drone) returning BeliefUpdaters (repeatable; "
                             "installed aeroexec.updaters entry points are always added)")
    web.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    path = Path(args.mission)
    try:
        choice = robots.chosen(args)
        catalog = choice.catalog(args.catalog)
        if choice.kind is not None and not args.world and choice.kind.world:
            args.world = str(choice.kind.world)  # the kind's own world, checked against and flown in
        world = chosen_world(args, default=args.drone == "sim")  # destinations checked against it
        mission = load_mission(path, catalog, world)
        if choice.kind is None:  # --library: found before flight (a robot kind brings its own behaviors)
            args.behavior_library = default_library(getattr(args, "library", ()))
            args.process_registry = default_processes(getattr(args, "processes", ()))
        return fly(args, catalog, mission, path.name, choice)
    except robots.RobotKindError as error:
        print(error, file=sys.stderr)
        return 2
    except (RunError, MissionFileError, WorldChoiceError, LibraryError, web.SurfaceError) as error:
        print(error, file=sys.stderr)
        return 1


def load_mission(path: Path, catalog: BehaviorCatalog, world: Any = None) -> Callable[[], Any] | TreeDocument:
    """Check a mission before flight (printing every problem), against ``world`` when given; the Python
    function or the tree to fly."""
    checked = check_mission(path, catalog, world)
    for problem in checked.problems:
        print(problem, file=sys.stderr)
    if checked.errors:
        count = len(checked.errors)
        raise RunError(f"{path}: {count} error{'s' if count != 1 else ''}; the mission will not fly")
    return checked.tree if checked.tree is not None else mission_function(path)


def make_drone(args: argparse.Namespace, choice: robots.RobotChoice | None = None) -> tuple[Drone, Any, bool]:
    """The robot (a drone unless ``--robot`` says), the world it moves in (obstacles for the planner), and
    whether it runs on simulated time."""
    from aeroexec.drones.sim import WorldError, default_world, load_world

    kind = choice.kind if choice is not None else None
    try:
        path = world_file(args, choice)
        world = load_world(path) if path else default_world()
    except WorldError as error:
        raise RunError(str(error)) from None
    if kind is not None:
        if args.drone != "sim" or kind.simulator is None:
            raise RunError(f"--robot {kind.name}: only its simulated robot can be flown from here")
        return kind.simulator(world, args.seed), world, True
    if args.drone == "sim":
        from aeroexec.drones.sim import SimulatedDrone

        return SimulatedDrone(world, seed=args.seed), world, True
    if args.drone.startswith("mavsdk:"):
        from aeroexec.drones.mavsdk import MavsdkDrone

        url = args.drone[len("mavsdk:"):]
        ready = getattr(args, "ready_timeout", READY_TIMEOUT)
        try:
            drone = MavsdkDrone(url, ready_timeout=ready)
        except ValueError as error:
            raise RunError(f"--drone {args.drone}: {error}") from None
        print(f"connecting to {url} (waiting up to {ready:g} s for the vehicle to be ready) ...", file=sys.stderr)
        if not drone.wait_ready(ready):
            why = "; ".join(drone.not_ready_because()) or "no answer"
            drone.close()
            raise RunError(f"--drone {args.drone}: the vehicle is not ready to fly after {ready:g} s: {why} "
                           f"(--ready-timeout gives it longer)")
        print(f"{drone.autopilot} vehicle ready on {url}", file=sys.stderr)
        return drone, world if args.world else None, False
    scheme, _, address = args.drone.partition(":")
    try:  # an installed adapter (an aeroexec.drones entry point)
        return make_adapter_drone(scheme, address), world if args.world else None, False
    except LibraryError as error:
        raise RunError(f"--drone {args.drone}: expected sim or mavsdk:URL (e.g. mavsdk:udpin://0.0.0.0:14540), "
                       f"or NAME:ADDRESS of an installed adapter; {error}") from None


def fly(args: argparse.Namespace, catalog: BehaviorCatalog, mission: Callable[[], Any] | TreeDocument,
        name: str, choice: robots.RobotChoice | None = None) -> int:
    live = live_view_wanted(args)
    fleet_name = getattr(args, "fleet", None)
    if fleet_name and not getattr(args, "name", None):
        raise RunError("--fleet needs --name D: this drone's name in the fleet")
    watched = live or web.wanted(args)  # someone watches: real time unless --speed says, questions wait for them
    operator = make_operator(args, watched)
    drone, world, simulated = make_drone(args, choice)
    paced = 1.0 if watched or fleet_name else None
    clock = SimulatedClock(speed=args.speed or paced) if simulated else WallClock()
    folder = make_output_folder(getattr(args, "output", None))
    try:
        updaters = default_updaters(drone, getattr(args, "updater", ()))
    except LibraryError as error:
        operator.close()
        drone.close()
        raise RunError(str(error)) from None
    options = choice.engine_options(drone) if choice is not None and choice.kind is not None else {
        "library": getattr(args, "behavior_library", None), "processes": getattr(args, "process_registry", None)}
    engine = Engine(drone, catalog=catalog, clock=clock, obstacles=world, operator=operator, output_dir=folder,
                    updaters=updaters, **options)
    link = None
    if fleet_name:
        from aeroexec.fleet.joined import join_fleet
        from aeroexec.fleet.transport import TransportError

        try:
            link = join_fleet(engine, fleet_name, args.name, folder, name, args.connect, args.token,
                              tuple(args.share), args.credentials)
            print(f"{args.name} joined fleet {fleet_name}", file=sys.stderr, flush=True)
        except (TransportError, ValueError) as error:
            engine.stop()
            operator.close()
            drone.close()
            raise RunError(str(error)) from None
    log_path = Path(args.log) if args.log else folder / "events.jsonl"
    try:
        meta = {"mission": name, "world": _absolute(world_file(args, choice)), "drone": args.drone,
                "seed": args.seed, "robot": getattr(args, "robot", "drone"), "output": str(folder)}
        flight_log = FlightLogWriter(engine, log_path, meta=meta)
    except OSError as error:
        engine.stop()
        operator.close()
        drone.close()
        raise RunError(f"the event log {log_path} cannot be written: {error}") from None
    print(f"event log: {log_path}", file=sys.stderr)
    lines = contextlib.ExitStack()
    if not live:
        lines.enter_context(whole_lines())  # the mission's print() and the events never share a line
        engine.log.subscribe(printer(None if args.quiet else sys.stdout))
    console = OperatorConsole(engine, folder, name, mission, live).start()  # control socket, live view, keys
    btlog = groot = browser = None
    faults: list[str] = []
    try:
        browser = web.start_console(args, engine, world, None if isinstance(mission, TreeDocument) else args.mission)
        try:
            if isinstance(mission, TreeDocument):
                tree_mission = TreeMission(mission, engine, name=name)
                btlog = BtlogWriter(tree_mission, folder / "mission.btlog", catalog)
                groot = web.start_groot(args, tree_mission, catalog)
                tree_mission.run(max_time=args.max_time)
            else:
                engine.run(mission, max_time=args.max_time, name=name)
        except KeyboardInterrupt:
            print("interrupted by the operator: aborting and landing (Ctrl-C again leaves the drone as it is)",
                  file=sys.stderr)
            engine.log.record("operator_interrupt", detail="Ctrl-C")
            engine.supervisor.execute("abort", "Ctrl-C: aborted by the operator", origin="keyboard")
        faults = end_flight(engine, link_grace=getattr(args, "link_grace", LINK_GRACE))
        if link is not None:  # the fleet hears how this drone's mission ended (telemetry's status)
            failed = engine.log.events(kind="mission_failed") or faults
            link.link.state = "failed" if failed else "completed" if engine.log.events(kind="mission_completed") \
                else "stopped"
            link.link.update(engine.memory, float("inf"))  # publish it once more before leaving
    except KeyboardInterrupt:
        print("interrupted again: leaving the drone as it is", file=sys.stderr)
        faults = ["the operator interrupted the end of the flight: the drone was left as it was"]
    finally:
        # how the run ended, in the log (the live view's header and the report show it): faults fail it
        record_run_status(engine.log, RunStatus(FAILED, faults) if faults else run_status(engine.log.events()))
        console.close()
        engine.stop()
        for surface in (browser, groot, link):
            if surface is not None:
                surface.close()
        flight_log.close()
        if btlog is not None:
            btlog.close()
        operator.close()
        drone.close()
        lines.close()
    return summary(engine, name, faults)


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


def summary(engine: Engine, name: str, faults: list[str] | tuple[str, ...] = ()) -> int:
    """Print how the run ended (the words of :mod:`~aeroexec.engine.supervision.run_status`); its exit status.
    With faults (link lost, landing failed, drone left armed or in the air) the run failed, whatever the mission
    did, and its last line says why: ``failed: ...``."""
    status = run_status(engine.log.events())  # as recorded at the end of the run
    word = status.word
    outcomes = [e for e in engine.log.events() if e.kind in {o.value for o in Outcome}]
    print(f"{name}: {word} at t={engine.now():.1f} s; {len(outcomes)} behavior events, "
          f"{sum(e.kind == 'GOAL_ACHIEVED' for e in outcomes)} goals achieved", file=sys.stderr)
    if word != COMPLETED and not faults:
        for reason in status.reasons[:5]:
            print(f"  {reason}", file=sys.stderr)
    if faults:
        print(f"failed: {'; '.join(faults)}", file=sys.stderr)
        return 1
    return status.exit_status


def world_file(args: argparse.Namespace, choice: robots.RobotChoice | None) -> str | None:
    """The world file the run uses: ``--world``, else its robot kind's (None: the built-in field)."""
    kind = choice.kind if choice is not None else None
    return args.world or (str(kind.world) if kind is not None and kind.world else None)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not (value >= 0 and value != float("inf")):
        raise argparse.ArgumentTypeError(f"must be a number of seconds >= 0, not {text}")
    return value


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
