"""``aeroexec fleet FLEET.yaml``: fly every drone of a fleet file in one process, one world, linked over Zenoh;
``aeroexec fleet --router``: a Zenoh router for fleets that span processes and machines.

The fleet's endpoint and token go to ``fleet.json`` in the output folder (``aeroexec ctl --fleet`` reads it).
Events print one line each, prefixed by the drone; the run ends with one summary line per drone, exit 0
only when every mission completed.
"""

from __future__ import annotations

import argparse
import os
import secrets
import signal
import sys
import threading
from typing import Any

from aeroexec.cli.catalog import chosen_catalog
from aeroexec.cli.flying import web
from aeroexec.cli.flying.mission_files import MissionFileError
from aeroexec.cli.run import RunError, load_mission
from aeroexec.cli.verify import add_home_argument
from aeroexec.cli.views.live import wanted as live_view_wanted
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.engine.supervision.output import make_output_folder
from aeroexec.engine.supervision.supervisor import is_flying
from aeroexec.fleet.fleet_json import FLEET_FILE, TOKEN_VARIABLE, write_fleet_file


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("fleet_file", nargs="?", metavar="FLEET.yaml", help="the fleet file (not with --router)")
    parser.add_argument("--router", action="store_true", help="run a Zenoh router until Ctrl-C")
    parser.add_argument("--listen", action="append", metavar="ENDPOINT",
                        help="where to listen (default: a free port on 127.0.0.1 for a fleet, "
                             "tcp/127.0.0.1:7447 for --router); repeatable")
    parser.add_argument("--connect", action="append", metavar="ENDPOINT",
                        help="join the fleet through this router instead of listening (e.g. tcp/127.0.0.1:7447); "
                             "with --router: another machine's router to link to")
    parser.add_argument("--speed", type=float, metavar="N",
                        help="simulated time N times faster than real time (default: real time with the live view, "
                             "else as fast as possible)")
    parser.add_argument("--plain", action="store_true",
                        help="one line per event, prefixed by the drone, instead of the live view (always so when "
                             "stdout is no terminal)")
    parser.add_argument("--quiet", action="store_true", help="print only the summary lines")
    parser.add_argument("--output", metavar="DIR", help="where each drone's event log goes (DIR/<drone>/)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    add_home_argument(parser)
    web.add_console_arguments(parser)
    parser.add_argument("--max-time", type=float, default=1800.0, metavar="S",
                        help="stop every mission after S seconds of mission time (default 1800)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.fleet.transport import TransportError

    try:
        if args.router:
            return serve_router(args.listen or ["tcp/127.0.0.1:7447"], args.connect or [])
        if not args.fleet_file:
            print("aeroexec fleet: give a fleet file, or --router", file=sys.stderr)
            return 2
        return fly_fleet(args)
    except TransportError as error:
        print(error, file=sys.stderr)
        return 1


def serve_router(listen: list[str], connect: list[str]) -> int:
    """A Zenoh router on ``listen``, linked to the routers at ``connect`` (other machines), until Ctrl-C."""
    from aeroexec.fleet.transport import open_session

    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda *_: stop.set())
    session = open_session("router", listen=listen, connect=connect)
    try:
        linked = f", linked to {', '.join(connect)}" if connect else ""
        print(f"zenoh router listening on {', '.join(listen)}{linked} (Ctrl-C to stop)", file=sys.stderr,
              flush=True)
        while not stop.wait(0.5):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        session.close()
        signal.signal(signal.SIGTERM, previous)
    return 0


def fly_fleet(args: argparse.Namespace) -> int:
    from aeroexec.drones.sim import WorldError
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet
    from aeroexec.fleet.node import FleetNode
    from aeroexec.fleet.runner import FleetRun
    from aeroexec.fleet.transport import free_endpoint, open_session
    from aeroexec.trees.mission_world import mission_world

    try:
        spec = load_fleet(args.fleet_file)
        catalog = chosen_catalog(args.catalog)
        missions = {d.name: load_mission(d.mission, catalog) for d in spec.drones}
        world = mission_world(None, spec.world, args.home)  # the fleet's world, at --home when given
    except FleetFileError as error:
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 1
    except (RunError, MissionFileError, WorldError) as error:
        print(error, file=sys.stderr)
        return 1
    for problem in spec.problems:
        print(problem, file=sys.stderr)
    token = spec.token or os.environ.get(TOKEN_VARIABLE) or secrets.token_hex(16)
    if args.connect:
        session, endpoints = open_session("client", connect=args.connect), list(args.connect)
    else:
        endpoints = args.listen or [free_endpoint()]
        session = open_session("router", listen=endpoints)
    folder = make_output_folder(args.output)
    try:
        write_fleet_file(folder, spec.name, endpoints, token)
        print(f"fleet {spec.name}: {len(spec.drones)} drones, link on {', '.join(endpoints)}; "
              f"token and endpoint in {folder / FLEET_FILE}", file=sys.stderr, flush=True)
        node = FleetNode(session, spec.name, token)
        live = live_view_wanted(args)  # a person at a terminal: paced at real time unless --speed says
        watched = live or web.wanted(args)  # in a browser too; questions then wait for an answer
        fleet = FleetRun(node, list(spec.drones), missions, world=world, catalog=catalog,
                         speed=args.speed or (1.0 if watched else None), output=folder,
                         telemetry_rate=spec.telemetry_rate,
                         operator=remote_operator if web.wanted(args) else None)
        view = None
        browser = web.serve_console(args, fleet.engines, world,
                                    {d.name: d.mission for d in spec.drones if str(d.mission).endswith(".py")})
        if live:
            from aeroexec.cli.views.fleet_view import FleetView

            view = FleetView(spec.name, fleet.engines, {m.name: m.link for m in fleet.members}).start()
        elif not args.quiet:
            for name, engine in fleet.engines.items():
                engine.log.subscribe(prefixed(name, sys.stdout))
        try:
            outcomes = fleet.run(max_time=args.max_time)
        except KeyboardInterrupt:
            print("interrupted by the operator: the fleet stops", file=sys.stderr)
            fleet.stop()
            fleet.close()
            outcomes = {m.name: m.outcome() for m in fleet.members}
        finally:
            if view is not None:
                view.stop()
            if browser is not None:
                browser.close()
            node.close()
    finally:
        session.close()
        (folder / FLEET_FILE).unlink(missing_ok=True)
    for member in fleet.members:
        print(summary_line(member, outcomes[member.name]), file=sys.stderr)
    return 0 if all(outcome == "completed" for outcome in outcomes.values()) else 1


def remote_operator() -> Any:
    """A drone's operator channel when the fleet is watched in a browser: questions wait for the console."""
    from aeroexec.engine.supervision.operator import RemoteOperator

    return RemoteOperator()


def summary_line(member: Any, outcome: str) -> str:
    engine = member.engine
    t = engine.drone.telemetry()
    goals = sum(e.kind == Outcome.GOAL_ACHIEVED.value for e in engine.log.events())
    silent = sorted(member.link.silent)
    return (f"{member.name}: {member.spec.mission.name} {outcome} at t={engine.now():.1f} s, {goals} goals achieved, "
            f"{'in the air' if is_flying(engine) else 'landed'} at "
            f"({t.position[0]:.1f}, {t.position[1]:.1f}), battery {t.battery_percent:.0f} %"
            + (f"; silent: {', '.join(silent)}" if silent else ""))


def prefixed(name: str, out: Any) -> Any:
    def show(event: EngineEvent) -> None:
        if event.kind != "node_status":
            print(f"{name:>4} | {event}", file=out, flush=True)

    return show
