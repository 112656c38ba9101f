"""``aeroexec fleet FLEET.yaml``: fly every drone of a fleet file in one world, linked over Zenoh, as one
:class:`~aeroexec.flight.FleetSession` (set up, flown and closed there): in one process (one flight session per
drone), or spread over worker processes in lockstep (``--workers N``; one per core for large fleets); ``aeroexec fleet
FLEET.yaml --router``: the fleet's Zenoh router, for fleets that span processes and machines; ``aeroexec fleet
FLEET.yaml --make-credentials DIR``: the fleet's CA and every identity, for several machines.

Sessions are mutual TLS with the fleet's credentials (made in the output folder when the file names none) and the
router enforces the fleet's access rules (:mod:`aeroexec.fleet.members`). The fleet's endpoint, token and operator
certificate go to ``fleet.json`` in the output folder (``aeroexec ctl --fleet`` reads it).
Events print one line each, prefixed by the drone; every drone's files go to ``<output>/<drone>/``, the fleet's
status to ``<output>/fleet_status.json``. Ctrl-C, SIGTERM, SIGHUP and the time limit land every drone. The run
ends with one summary line per drone; exit 0 only when every drone's flight completed, else 1.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from pathlib import Path
from typing import Any

from aeroexec.cli.run import EXIT_HELP, add_pacing_arguments, add_plugin_arguments, add_surface_arguments, say
from aeroexec.cli.verify import add_home_argument
from aeroexec.cli.views.choice import wanted as live_view_wanted
from aeroexec.engine.events import EngineEvent
from aeroexec.fleet.fleet_json import FLEET_FILE, TOKEN_VARIABLE, write_fleet_file
from aeroexec.flight.fleet import STATUS_FILE, FleetSession, event_line, fleet_exit_status
from aeroexec.flight.output import prepare_output
from aeroexec.flight.run_status import LOG_INCOMPLETE
from aeroexec.flight.signals import ending_signals
from aeroexec.flight.spec import FlightError, FlightSpec


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("fleet_file", metavar="FLEET.yaml", help="the fleet file")
    parser.epilog = "exit status: 0 when every drone's flight completed, else 1 (each drone's status is in its " \
                    "summary line and fleet_status.json: " + EXIT_HELP.removeprefix("exit status: ") + ")"
    parser.add_argument("--router", action="store_true", help="run the fleet's Zenoh router until Ctrl-C")
    parser.add_argument("--make-credentials", metavar="DIR",
                        help="make the fleet's CA and every identity its file names in DIR (the router's for the "
                             "hosts of --listen), then exit")
    parser.add_argument("--listen", action="append", metavar="ENDPOINT",
                        help="where to listen (default: a free port on 127.0.0.1 for a fleet, "
                             "tls/127.0.0.1:7447 for --router); repeatable")
    parser.add_argument("--connect", action="append", metavar="ENDPOINT",
                        help="join the fleet through its router instead of listening (e.g. tls/127.0.0.1:7447), "
                             "with the identities the fleet file names; with --router: the fleet's router on "
                             "another machine, to link to")
    add_pacing_arguments(parser)
    parser.add_argument("--workers", type=int, metavar="N",
                        help="fly the drones in N worker processes, in lockstep through the fleet's router (default: "
                             "one for every 100 drones, at most one per core; 1 with --web, the live view or "
                             "--connect)")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)  # started by the coordinator
    parser.add_argument("--output", metavar="DIR", help="where each drone's files go (DIR/<drone>/)")
    parser.add_argument("--mcap", metavar="FILE",
                        help="write an MCAP recording of the fleet to FILE while flying, each drone's topics under "
                             "its name (as aeroexec export --mcap of the fleet's folder; the drones in this process)")
    parser.add_argument("--answers", metavar="FILE",
                        help="answer the missions' questions from FILE (YAML: question -> answer, or a list)")
    add_home_argument(parser)
    add_plugin_arguments(parser)
    add_surface_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from aeroexec.fleet.credentials import CredentialsError
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet
    from aeroexec.fleet.transport import TransportError

    try:
        if args.router or args.make_credentials:
            spec = load_fleet(args.fleet_file)
            if args.make_credentials:
                return make_credentials(spec, args.make_credentials, args.listen or [])
            return serve_router(spec, args.listen or ["tls/127.0.0.1:7447"], args.output, args.connect or [])
        return fly_fleet(args)
    except FleetFileError as error:
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 1
    except (TransportError, CredentialsError) as error:
        print(error, file=sys.stderr)
        return 1


def make_credentials(spec: Any, folder: str, listen: list[str]) -> int:
    """The fleet's credentials in ``folder``; one line per identity."""
    from aeroexec.fleet.credentials import LOCAL_HOSTS
    from aeroexec.fleet.members import make_credentials as make
    from aeroexec.fleet.transport import endpoint_host

    made = make(spec, Path(folder), (*LOCAL_HOSTS, *map(endpoint_host, listen)))
    for name, identity in made.items():
        print(f"{name}: {identity.certificate} (key {identity.key})")
    print(f"the fleet's CA: {Path(folder) / 'ca.pem'}; keep {Path(folder) / 'ca.key'} off the drones",
          file=sys.stderr)
    return 0


def serve_router(spec: Any, listen: list[str], output: str | None, connect: list[str]) -> int:
    """The fleet's Zenoh router on ``listen`` (its access rules from ``spec``), linked to its routers at ``connect``
    (other machines), until Ctrl-C."""
    from aeroexec.fleet.members import listen as open_router

    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda *_: stop.set())
    try:
        folder = prepare_output(output)
    except FlightError as error:
        print(error, file=sys.stderr)
        return 2
    membership = open_router(spec, listen, folder, connect)
    try:
        # what ctl --fleet NAME --run DIR needs on the router's machine: its endpoints and those of the routers it
        # links to (each a path a command takes at once), the operator and the roster
        paths = list(dict.fromkeys([*membership.endpoints, *connect]))
        write_fleet_file(folder, spec.name, paths, spec.token or os.environ.get(TOKEN_VARIABLE, ""),
                         membership.operator, (d.name for d in spec.drones))
        linked = f", linked to {', '.join(connect)}" if connect else ""
        print(f"zenoh router of fleet {spec.name} listening on {', '.join(listen)}{linked} (Ctrl-C to stop)",
              file=sys.stderr, flush=True)
        while not stop.wait(0.5):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        membership.close()
        signal.signal(signal.SIGTERM, previous)
    return 0


def fly_fleet(args: argparse.Namespace) -> int:
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet

    try:
        spec = load_fleet(args.fleet_file)
    except FleetFileError as error:
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 1
    for problem in spec.problems:
        print(problem, file=sys.stderr)
    if not spec.flown:
        print(f"{spec.file}: no drone has a mission: nothing flies here (run --router for a fleet flown elsewhere)",
              file=sys.stderr)
        return 1
    live = live_view_wanted(args)  # a person at a terminal: paced at real time unless --speed says
    watched = live or args.web is not None  # in a browser too; questions then wait for an answer
    base = FlightSpec(mission=Path(args.fleet_file), robot=args.robot, world=str(spec.world) if spec.world else None,
                      catalog=args.catalog, rules=tuple(args.rules), library=tuple(args.library),
                      processes=tuple(args.processes),
                      updaters=tuple(args.updater), max_time=args.max_time, home=args.home,
                      answers=args.answers)
    if args.worker:
        from aeroexec.flight.fleet.worker import serve

        with ending_signals():
            return serve(spec)
    workers = worker_count(args, len(spec.flown), live)
    if workers is None:
        return 2
    if workers > 1 and live:
        say(f"with {workers} workers, events print as lines (--workers 1 for the live view)")
    fleet = FleetSession(spec, base, output=args.output, listen=args.listen or (), connect=args.connect or (),
                         workers=workers, speed=args.speed or (1.0 if watched else None),
                         token=os.environ.get(TOKEN_VARIABLE), remote_questions=args.web is not None,
                         recording=args.mcap, quiet=args.quiet, verbose=args.verbose,
                         lines=lambda line: print(line, flush=True), notify=say,
                         report=lambda problem: print(problem, file=sys.stderr))
    with ending_signals():
        try:
            fleet.open()
            if args.web is not None:
                fleet.serve_console(args.web, args.web_host)
        except FlightError as error:
            print(error, file=sys.stderr)
            return 2 if error.usage else 1
        except KeyboardInterrupt as interrupt:
            print(f"interrupted before take-off ({getattr(interrupt, 'signal_name', 'Ctrl-C')}): nothing flew",
                  file=sys.stderr)
            return 130
        try:
            elsewhere = [d.name for d in spec.drones if d.mission is None]
            where = (f"{len(spec.flown)} drones in {len(fleet.worker_fleet.shares)} workers"
                     if fleet.worker_fleet is not None else
                     f"{len(spec.flown)} drones here" + (f", {', '.join(elsewhere)} elsewhere" if elsewhere else ""))
            say(f"fleet {spec.name}: {where}, link on {', '.join(fleet.endpoints)}; token, endpoint and operator "
                f"credentials in {fleet.folder / FLEET_FILE}")
            drones = _fly(fleet, spec.name, live, args.quiet)
        finally:
            fleet.close()
    for record in drones.values():
        print(record["summary"], file=sys.stderr)
    print(f"fleet {spec.name}: the status of each drone is in {fleet.folder / STATUS_FILE}", file=sys.stderr)
    status = fleet_exit_status(drones)
    if fleet.recording is not None:
        if fleet.recording.error is not None:
            print(f"fleet {spec.name}: the recording {args.mcap} is incomplete ({fleet.recording.error}): exit "
                  f"status {LOG_INCOMPLETE}", file=sys.stderr)
            return status or LOG_INCOMPLETE
        print(f"fleet {spec.name}: recording in {args.mcap}", file=sys.stderr)
    return status


def worker_count(args: argparse.Namespace, drones: int, live: bool) -> int | None:
    """How many worker processes fly the fleet; None (said why) when the options cannot go together."""
    from aeroexec.flight.fleet.workers import default_workers

    one_process = [what for what, given in (("--web", args.web is not None), ("--connect", bool(args.connect)),
                                            ("--mcap", getattr(args, "mcap", None) is not None)) if given]
    if args.workers is None:
        return 1 if one_process or live else default_workers(drones)
    if args.workers < 1:
        print(f"aeroexec fleet: --workers {args.workers}: at least 1", file=sys.stderr)
        return None
    if args.workers > 1 and one_process:
        print(f"aeroexec fleet: {' and '.join(one_process)} needs every drone in this process: use --workers 1",
              file=sys.stderr)
        return None
    return min(args.workers, drones)


def _fly(fleet: FleetSession, name: str, live: bool, quiet: bool) -> dict[str, dict[str, Any]]:
    view = None
    if fleet.flight is not None and live:
        from aeroexec.cli.views.fleet_view import FleetView

        view = FleetView(name, fleet.flight.engines, {m.name: m.link for m in fleet.flight.members}).start()
    elif fleet.flight is not None and not quiet:
        for drone, engine in fleet.flight.engines.items():
            engine.log.subscribe(prefixed(drone, sys.stdout))
    try:
        return fleet.fly()
    finally:
        if view is not None:
            view.stop()


def prefixed(name: str, out: object) -> object:
    def show(event: EngineEvent) -> None:
        if (line := event_line(name, event)) is not None:
            print(line, file=out, flush=True)

    return show
