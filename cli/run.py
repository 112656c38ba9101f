"""``aeroexec run MISSION``: check a mission (Python, a behavior tree, TML or a QGroundControl plan), then fly it
on the built-in simulator or a MAVSDK drone: the arguments become a :class:`~aeroexec.flight.FlightSpec`, a
:class:`~aeroexec.flight.FlightSession` flies it, and this module prints what happens.

The events are printed as they happen (or shown in the live view at a terminal). However the run ends — the
mission, the time limit, ``aeroexec ctl abort``, Ctrl-C, SIGTERM or SIGHUP — the drone lands before the command
returns; its last line says how the run ended and where its files are.

``aeroexec run --resume RUN_DIR`` goes on with an interrupted run (killed, suspended, aborted) from where its
journal says it stopped (``flight/journal/``).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import sys
from collections.abc import Callable
from pathlib import Path

from aeroexec.cli.lines import whole_lines
from aeroexec.cli.main import lasting
from aeroexec.cli.verify import add_home_argument, add_vehicle_argument
from aeroexec.cli.views.choice import wanted as live_view_wanted
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.flight.run_status import COMPLETED, FlightOutcome
from aeroexec.flight.session import FlightSession
from aeroexec.flight.signals import ending_signals, interrupts_held
from aeroexec.flight.spec import LINK_GRACE, MAX_TIME, READY_TIMEOUT, FleetJoin, FlightError, FlightSpec
from aeroexec.trees import formats

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import TextIO

logger = logging.getLogger(__name__)

EXIT_HELP = ("exit status: 0 completed, 3 completed with refused requests, 1 failed (a safety rule broken too), "
             "4 aborted (the operator, Ctrl-C, SIGTERM, SIGHUP), 5 suspended (a safety reaction such as LAND on low "
             "battery cut the mission short), 6 the event log or journal is incomplete or photos could not be saved "
             "(a full disk), 2 an option that cannot be used, 130 interrupted before take-off")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    mission = parser.add_argument(
        "mission", nargs="?", help=f"the mission: a Python program with a mission() or runMission() function, or a "
                                   f"behavior tree, in one of the formats {formats.described()}; with --resume, "
                                   f"the interrupted run's unless given")
    mission.completer = formats.complete_mission_files  # type: ignore[attr-defined]  # argcomplete
    parser.add_argument("--resume", metavar="RUN_DIR",
                        help="go on with the interrupted run in RUN_DIR (killed, suspended, aborted) from where its "
                             "journal says it stopped: as it was flown (mission, drone, world, catalog, plugins, "
                             "fleet), with this command line's pacing, time limit and surfaces")
    parser.set_defaults(script_args=[])
    parser.epilog = (f"A script's own arguments follow a lone --, as python3 script.py would be given them (its "
                     f"argparse options, ROS 2's --ros-args -p NAME:=VALUE): aeroexec run mission.py -- -n drone0 "
                     f"--ros-args -p height:=3.0. {EXIT_HELP}")
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
    fleet.add_argument("--trust", action="append", default=[], metavar="PREDICATE=K",
                       help="believe a belief of PREDICATE another drone says only while K distinct members say it "
                            "(as the fleet file's trust:), e.g. --trust code=2 (repeatable)")
    fleet.add_argument("--token", metavar="T", help="the fleet's token for operator commands (default: "
                                                    "$AEROEXEC_FLEET_TOKEN, else a new one in fleet.json)")


def add_plugin_arguments(parser: argparse.ArgumentParser) -> None:
    """The robot kind, catalog and plugins (run, fleet)."""
    from aeroexec.cli.verify import add_library_arguments, add_safety_rules_argument

    parser.add_argument("--robot", default="drone", metavar="KIND",
                        help="the kind of robot: drone (default), or one an installed plugin adds, e.g. rover")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the robot kind's)")
    add_library_arguments(parser)
    add_safety_rules_argument(parser)
    parser.add_argument("--updater", action="append", default=[], metavar="MODULE:ATTR",
                        help="belief updaters to add: a callable (drone) returning BeliefUpdaters (repeatable; "
                             "installed aeroexec.updaters entry points are always added)")


def add_flight_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of one flight (run, and the behavior-tree runner)."""
    add_plugin_arguments(parser)
    parser.add_argument("--drone", default="sim", metavar="sim|mavsdk:URL|NAME:ADDRESS",
                        help="the built-in simulated drone (default), a MAVSDK vehicle "
                             "(e.g. mavsdk:udpin://0.0.0.0:14540), or an installed adapter (aeroexec.drones "
                             "entry point NAME)")
    parser.add_argument("--ready-timeout", type=seconds, default=READY_TIMEOUT, metavar="S",
                        help=f"how long a MAVSDK vehicle may take to be ready to fly: connected, armable, with "
                             f"global and home positions (default {READY_TIMEOUT:g} s)")
    parser.add_argument("--link-grace", type=seconds, default=LINK_GRACE, metavar="S",
                        help=f"when the link to the drone is down at the end of the mission, keep trying to reach it "
                             f"this long to land it (default {LINK_GRACE:g} s; its own failsafe acts meanwhile)")
    parser.add_argument("--world", metavar="FILE", help="the simulated world; literal destinations are checked "
                                                        "against it (default: the robot kind's, an open field "
                                                        "around a plan or waypoint file, else the built-in one)")
    add_home_argument(parser)
    add_vehicle_argument(parser)
    parser.add_argument("--event", action="append", default=[], metavar="TOPIC[=DATA]",
                        help="an event given at launch: the belief event(TOPIC, DATA) (DATA empty without =), which "
                             "Aerostack2's WaitForEvent TOPIC and a mission's queries see, as after aeroexec ctl add "
                             "(repeatable), e.g. --event start=go")
    parser.add_argument("--alert", action="append", default=[], metavar="TOPIC[=DATA]",
                        help="an alert given at launch: the belief alert(TOPIC, DATA), which WaitForAlert TOPIC sees "
                             "(repeatable)")
    add_pacing_arguments(parser)
    parser.add_argument("--seed", type=int, default=0, help="seed of the simulated sensors")
    parser.add_argument("--log", metavar="FILE",
                        help="write the event log (one JSON object per line) to FILE (default: events.jsonl "
                             "in the output folder)")
    parser.add_argument("--output", metavar="DIR",
                        help="where the event log, photos, videos and maps go (default: "
                             "aeroexec_output/<date-time>)")
    parser.add_argument("--answers", metavar="FILE",
                        help="answer the mission's questions from FILE (YAML: question -> answer, or a list); "
                             "default: ask at the terminal when interactive, else the first possible answer")
    add_surface_arguments(parser)
    parser.add_argument("--groot", nargs="?", type=int, const=1667, metavar="PORT",
                        help="serve tree missions to Groot2 (its publisher protocol on PORT and PORT+1, default 1667)")
    parser.add_argument("--mcap", metavar="FILE",
                        help="write an MCAP recording of the flight to FILE while flying (the topics of aeroexec "
                             "export --mcap: ROS 2 pose, velocity, fix, battery, /tf, route; aeroexec's records)")
    parser.add_argument("--foxglove", nargs="?", type=int, const=8765, metavar="PORT",
                        help="serve the flight live to Foxglove (its WebSocket protocol on --web-host's address, "
                             "PORT 8765 without PORT, 0 for a free one): the topics of --mcap; simulated time then "
                             "runs at real time unless --speed says")


def add_pacing_arguments(parser: argparse.ArgumentParser) -> None:
    """How fast simulated time runs, how long a mission may take, and what is printed (run, fleet)."""
    parser.add_argument("--speed", type=float, metavar="N",
                        help="simulated time N times faster than real time (default: real time with the live "
                             "view in a terminal; as fast as possible with --plain, --quiet or no terminal)")
    parser.add_argument("--max-time", type=float, default=MAX_TIME, metavar="S",
                        help=f"stop the mission after S seconds of mission time (default {MAX_TIME:g}); the drone "
                             f"then lands")
    parser.add_argument("--quiet", action="store_true", help="print only the outcome")
    parser.add_argument("--plain", action="store_true",
                        help="one line per event instead of the live view (always so when stdout is no terminal)")


def add_surface_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--web", nargs="?", type=int, const=0, metavar="PORT",
                        help="serve the operator console in a browser on 127.0.0.1:PORT (a free port without PORT); "
                             "the URL with its token is printed")
    parser.add_argument("--web-host", default="127.0.0.1", metavar="HOST",
                        help="the address the console listens on (default 127.0.0.1: this machine only)")


def trust_arguments(words: list[str]) -> tuple[tuple[str, int], ...]:
    """``--trust PREDICATE=K`` as (predicate, k) pairs; FlightError (usage) naming the one that is not."""
    from aeroexec.fleet.fleet_file import PREDICATE

    trust: dict[str, int] = {}
    for word in words:
        predicate, _, count = word.partition("=")
        if not PREDICATE.match(predicate) or not count.isascii() or not count.isdigit() or len(count) > 6 or \
                int(count) < 1:
            raise FlightError(f"--trust {word}: give PREDICATE=K, a predicate's name and how many distinct members "
                              f"(at least 1) must say a belief of it, e.g. --trust code=2", usage=True)
        trust[predicate] = int(count)
    return tuple(trust.items())


def flight_spec(args: argparse.Namespace, watched: bool) -> FlightSpec:
    """The flight the arguments ask for; ``watched``: someone watches (live view, browser), so simulated time
    runs at real time unless ``--speed`` says, and questions wait for an answer."""
    if getattr(args, "resume", None):
        return resumed_spec(args, watched)
    if not args.mission:
        raise FlightError("aeroexec run: give the mission (a file), or --resume RUN_DIR", usage=True)
    fleet = None
    if getattr(args, "fleet", None):
        if not args.name:
            raise FlightError("--fleet needs --name D: this drone's name in the fleet", usage=True)
        fleet = FleetJoin(args.fleet, args.name, tuple(args.connect or ()), args.token, tuple(args.share),
                          credentials=args.credentials, trust=trust_arguments(getattr(args, "trust", None) or []))
    paced = 1.0 if watched or fleet is not None else None
    return FlightSpec(mission=Path(args.mission), robot=args.robot, drone=args.drone, world=args.world,
                      home=args.home, catalog=args.catalog, vehicle=getattr(args, "vehicle", None),
                      rules=tuple(args.rules), library=tuple(args.library),
                      processes=tuple(args.processes), safety_rules=tuple(args.safety_rules),
                      updaters=tuple(args.updater), speed=args.speed or paced, seed=args.seed, max_time=args.max_time,
                      output=args.output, log=args.log, answers=args.answers,
                      remote_questions=watched, interactive=sys.stdin is not None and sys.stdin.isatty(),
                      web=args.web, web_host=args.web_host, groot=args.groot, link_grace=args.link_grace,
                      ready_timeout=args.ready_timeout, fleet=fleet, mcap=getattr(args, "mcap", None),
                      foxglove=getattr(args, "foxglove", None), beliefs=launch_beliefs(args),
                      script_args=tuple(getattr(args, "script_args", None) or ()))


def launch_beliefs(args: argparse.Namespace) -> tuple[str, ...]:
    """``--event TOPIC[=DATA]`` and ``--alert TOPIC[=DATA]`` as the beliefs ``event(TOPIC, DATA)`` and
    ``alert(TOPIC, DATA)`` (topic and data quoted: any text); FlightError (usage) naming one without a topic."""
    from aeroexec.beliefs import BeliefError, parse_belief

    beliefs = []
    for kind in ("event", "alert"):
        for word in getattr(args, kind, None) or ():
            topic, _, data = word.partition("=")
            topic = topic.strip().lstrip("/")
            if not topic:
                raise FlightError(f"--{kind} {word}: give TOPIC[=DATA], the topic its WaitFor{kind.title()} names, "
                                  f"e.g. --{kind} start=go", usage=True)
            text = f"{kind}({_quoted(topic)}, {_quoted(data.strip())})"
            try:
                parse_belief(text)
            except (BeliefError, ValueError) as error:
                raise FlightError(f"--{kind} {word}: {error}", usage=True) from None
            beliefs.append(text)
    return tuple(beliefs)


def _quoted(text: str) -> str:
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def resumed_spec(args: argparse.Namespace, watched: bool) -> FlightSpec:
    """The interrupted run's flight, as its journal says, with this command line's pacing and surfaces."""
    from aeroexec.flight.journal import JournalError, resume_spec

    paced = 1.0 if watched else None
    try:
        return resume_spec(args.resume, mission=args.mission, drone=args.drone if args.drone != "sim" else None,
                           token=getattr(args, "token", None), credentials=getattr(args, "credentials", None),
                           speed=args.speed or paced, max_time=args.max_time,
                           answers=args.answers, remote_questions=watched,
                           interactive=sys.stdin is not None and sys.stdin.isatty(), web=args.web,
                           web_host=args.web_host, groot=args.groot, link_grace=args.link_grace,
                           ready_timeout=args.ready_timeout, mcap=getattr(args, "mcap", None),
                           foxglove=getattr(args, "foxglove", None))
    except JournalError as error:
        raise FlightError(str(error)) from None


def run(args: argparse.Namespace) -> int:
    live = live_view_wanted(args)
    with ending_signals():  # SIGTERM and SIGHUP end the run as Ctrl-C does: abort, land, close the log
        try:
            spec = flight_spec(args, watched=live or args.web is not None or args.foxglove is not None)
            drones = fleet_of_script(args, spec)
            if drones:
                return fly_script_fleet(args, spec, drones, live)
            session = FlightSession(spec, notify=say, report=lambda problem: print(problem, file=sys.stderr))
            with lasting():  # what the start makes lives as long as the run
                session.open()
        except FlightError as error:
            print(error, file=sys.stderr)
            return 2 if error.usage else 1
        except KeyboardInterrupt as interrupt:
            print(f"interrupted before take-off ({getattr(interrupt, 'signal_name', 'Ctrl-C')}): nothing flew",
                  file=sys.stderr)
            return 130
        say(f"commands: aeroexec ctl pause|resume|abort|suspend|inhibit|answer|add|remove|status (this run: "
            f"--run {session.folder})")
        try:
            with contextlib.ExitStack() as output:
                if live:
                    from aeroexec.cli.views.live import LiveConsole  # here: a run with --plain never shows it

                    output.enter_context(LiveConsole(session.engine, spec.name, session.mission))
                else:
                    output.enter_context(whole_lines())  # the mission's print() and the events never share a line
                    session.engine.log.subscribe(printer(None if args.quiet else sys.stdout))
                session.fly()
        except KeyboardInterrupt:
            if session.outcome is None:
                raise
            logger.info("a signal came after the run ended: nothing was left to stop")
        try:  # the run has ended: a signal now has nothing to stop, and the summary is printed whole
            with interrupts_held():
                return summary(session, session.outcome)
        except KeyboardInterrupt:
            logger.info("a signal came after the run ended: nothing was left to stop")
            return session.outcome.exit_status


def fleet_of_script(args: argparse.Namespace, spec: FlightSpec) -> tuple[str, ...]:
    """The drones of a script that names several (an Aerostack2 swarm), when this run flies it on the simulator
    from its start; empty otherwise (the run flies one drone)."""
    from aeroexec.flight.missions import script_drones
    from aeroexec.flight.robot import robot_choice

    if getattr(args, "resume", None) or spec.fleet is not None or spec.drone != "sim" or \
            robot_choice(spec.robot).kind is not None:
        return ()
    drones = script_drones(spec.mission)
    return drones if len(drones) > 1 else ()


def fly_script_fleet(args: argparse.Namespace, spec: FlightSpec, drones: tuple[str, ...], live: bool) -> int:
    """Fly the script ``spec`` names with a fleet made for it, one drone per name of ``drones``, in this process;
    the fleet's exit status (0 only when every drone's flight completed)."""
    from aeroexec.fleet.credentials import CredentialsError
    from aeroexec.fleet.transport import TransportError
    from aeroexec.flight.fleet import STATUS_FILE, drone_status, fleet_exit_status, summary_line
    from aeroexec.flight.fleet.script_fleet import SPACING, open_script_fleet, spawned
    from aeroexec.flight.output import prepare_output
    from aeroexec.flight.robot import load_world, robot_choice

    from aeroexec.extras import MissingExtra

    for option, given in (("--web", args.web is not None), ("--groot", args.groot is not None),
                          ("--mcap", getattr(args, "mcap", None) is not None),
                          ("--foxglove", getattr(args, "foxglove", None) is not None), ("--log", bool(args.log))):
        if given:
            raise FlightError(f"{spec.mission}: the script flies {len(drones)} drones ({', '.join(drones)}); "
                              f"{option} is for one drone: fly it with a fleet file (aeroexec fleet) for {option}",
                              usage=True)
    folder = prepare_output(args.output)
    world = load_world(robot_choice(spec.robot).world_file(spec.world), mission=spec.mission, home=spec.home)
    placed = "where its world spawns them" if spawned(drones, world) else f"{SPACING:g} m apart"
    say(f"{spec.mission.name} flies {len(drones)} drones ({', '.join(drones)}), {placed}, as a fleet "
        f"in this process; each drone's files in {folder}/<drone>/")
    try:
        fleet = open_script_fleet(spec, drones, folder, world, notify=say,
                                  report=lambda problem: print(problem, file=sys.stderr),
                                  remote_questions=live)
    except (MissingExtra, TransportError, CredentialsError) as error:
        print(f"{spec.mission}: the script flies {len(drones)} drones ({', '.join(drones)}) as a fleet: {error}",
              file=sys.stderr)
        return 1
    try:
        if not args.quiet:
            for drone, engine in fleet.flight.engines.items():
                engine.log.subscribe(_prefixed(drone))
        with whole_lines():
            outcomes = fleet.flight.fly()
    finally:
        fleet.close()
    for member in fleet.flight.members:
        print(summary_line(member, outcomes[member.name]), file=sys.stderr)
    print(f"{spec.mission.name}: the status of each drone is in {folder / STATUS_FILE}", file=sys.stderr)
    return fleet_exit_status({name: drone_status(outcome) for name, outcome in outcomes.items()})


def _prefixed(drone: str) -> Callable[[EngineEvent], None]:
    from aeroexec.flight.fleet import event_line

    def show(event: EngineEvent) -> None:
        if (line := event_line(drone, event)) is not None:
            print(line, flush=True)

    return show


def say(text: str) -> None:
    """A message for the operator, on stderr."""
    print(text, file=sys.stderr, flush=True)


def summary(session: FlightSession, outcome: FlightOutcome) -> int:
    """Print how the run ended and where its files are; its exit status. The summary goes to stderr, and to
    stdout as well when that is another file (``> run.log`` keeps it beside the events)."""
    events = session.engine.log.events()
    status = outcome.status
    outcomes = [e for e in events if e.kind in {o.value for o in Outcome}]
    goals = sum(e.kind == "GOAL_ACHIEVED" for e in outcomes)
    lines = [f"{session.spec.name}: {status.word} at t={session.engine.now():.1f} s; "
             f"{_count(len(outcomes), 'behavior event')}, {_count(goals, 'goal')} achieved; "
             f"files in {session.folder}"]
    if status.word != COMPLETED and not outcome.faults:
        lines += [f"  {reason}" for reason in status.reasons[:5]]
    if outcome.photos_not_saved is not None:
        lines.append(f"photos could not be saved ({outcome.photos_not_saved})")
    if outcome.log_incomplete is not None:
        lines.append(f"the event log is incomplete ({outcome.log_incomplete})")
    if outcome.faults:
        lines.append(f"failed: {'; '.join(outcome.faults)}")
    if outcome.photos_not_saved is not None or outcome.log_incomplete is not None:
        lines[-1] += f": exit status {outcome.exit_status}"  # the one the process returns (6 unless it failed)
    text = "\n".join(lines)
    print(text, file=sys.stderr, flush=True)
    if not _same_file(sys.stdout, sys.stderr) and not sys.stdout.isatty():
        with contextlib.suppress(OSError, ValueError):
            print(text, file=sys.stdout, flush=True)
    return outcome.exit_status


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _same_file(one: TextIO, other: TextIO) -> bool:
    try:
        a, b = os.fstat(one.fileno()), os.fstat(other.fileno())
    except (OSError, ValueError, AttributeError):
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not (value >= 0 and value != float("inf")):
        raise argparse.ArgumentTypeError(f"must be a number of seconds >= 0, not {text}")
    return value


def printer(out: TextIO | None) -> Callable[[EngineEvent], None]:
    """Each event as a line on ``out``; once ``out`` is closed (``| head``), the flight goes on unprinted."""
    closed = False

    def show(event: EngineEvent) -> None:
        nonlocal closed
        if out is None or closed:
            return
        try:
            print(_shown(event), file=out, flush=True)
        except (BrokenPipeError, ValueError):
            closed = True
            _detach_stdout()

    return show


def _detach_stdout() -> None:
    """Standard output was closed by its reader: send what is still written there nowhere."""
    with contextlib.suppress(OSError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.__stdout__.fileno())
        os.close(devnull)


def _shown(event: EngineEvent) -> str:
    """An event as a line; a tree node's status change is indented at the node's depth in the tree."""
    if event.kind != "node_status":
        return str(event)
    data = event.data
    return f"[{event.time:8.2f}] tree {'  ' * int(data.get('depth', 0))}{data.get('node')}: " \
           f"{data.get('old')} -> {data.get('new')}"

