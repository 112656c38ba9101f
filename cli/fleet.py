"""``aeroexec fleet FLEET.yaml``: fly every drone of a fleet file in one process, one world, linked over Zenoh;
``aeroexec fleet FLEET.yaml --router``: the fleet's Zenoh router, for fleets that span processes and machines;
``aeroexec fleet FLEET.yaml --make-credentials DIR``: the fleet's CA and every identity, for several machines.

Sessions are mutual TLS with the fleet's credentials (made in the output folder when the file names none) and the
router enforces the fleet's access rules (:mod:`aeroexec.fleet.members`). The fleet's endpoint, token and operator
certificate go to ``fleet.json`` in the output folder (``aeroexec ctl --fleet`` reads it).
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
from aeroexec.cli.views.live import wanted as live_view_wanted
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.engine.supervision.output import make_output_folder
from aeroexec.engine.supervision.supervisor import is_flying
from aeroexec.fleet.fleet_json import FLEET_FILE, TOKEN_VARIABLE, write_fleet_file


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("fleet_file", metavar="FLEET.yaml", help="the fleet file")
    parser.add_argument("--router", action="store_true", help="run the fleet's Zenoh router until Ctrl-C")
    parser.add_argument("--make-credentials", metavar="DIR",
                        help="make the fleet's CA and every identity its file names in DIR (the router's for the "
                             "hosts of --listen), then exit")
    parser.add_argument("--listen", action="append", metavar="ENDPOINT",
                        help="where to listen (default: a free port on 127.0.0.1 for a fleet, "
                             "tls/127.0.0.1:7447 for --router); repeatable")
    parser.add_argument("--connect", action="append", metavar="ENDPOINT",
                        help="join the fleet through its router instead of listening (e.g. tls/127.0.0.1:7447), "
                             "with the identities the fleet file names")
    parser.add_argument("--speed", type=float, metavar="N",
                        help="simulated time N times faster than real time (default: real time with the live view, "
                             "else as fast as possible)")
    parser.add_argument("--plain", action="store_true",
                        help="one line per event, prefixed by the drone, instead of the live view (always so when "
                             "stdout is no terminal)")
    parser.add_argument("--quiet", action="store_true", help="print only the summary lines")
    parser.add_argument("--output", metavar="DIR", help="where each drone's event log goes (DIR/<drone>/)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    web.add_console_arguments(parser)
    parser.add_argument("--max-time", type=float, default=1800.0, metavar="S",
                        help="stop every mission after S seconds of mission time (default 1800)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.fleet.credentials import CredentialsError
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet
    from aeroexec.fleet.transport import TransportError

    try:
        if args.router or args.make_credentials:
            spec = load_fleet(args.fleet_file)
            if args.make_credentials:
                return make_credentials(spec, args.make_credentials, args.listen or [])
            return serve_router(spec, args.listen or ["tls/127.0.0.1:7447"], args.output)
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
    from pathlib import Path

    from aeroexec.fleet.credentials import LOCAL_HOSTS
    from aeroexec.fleet.members import make_credentials as make
    from aeroexec.fleet.transport import endpoint_host

    made = make(spec, Path(folder), (*LOCAL_HOSTS, *map(endpoint_host, listen)))
    for name, identity in made.items():
        print(f"{name}: {identity.certificate} (key {identity.key})")
    print(f"the fleet's CA: {Path(folder) / 'ca.pem'}; keep {Path(folder) / 'ca.key'} off the drones",
          file=sys.stderr)
    return 0


def serve_router(spec: Any, listen: list[str], output: str | None) -> int:
    """The fleet's Zenoh router on ``listen`` (its access rules from ``spec``) until Ctrl-C."""
    from aeroexec.fleet.members import listen as open_router

    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda *_: stop.set())
    membership = open_router(spec, listen, make_output_folder(output))
    try:
        print(f"zenoh router of fleet {spec.name} listening on {', '.join(listen)} (Ctrl-C to stop)",
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
    from aeroexec.drones.sim import WorldError, default_world, load_world
    from aeroexec.fleet import members
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet
    from aeroexec.fleet.runner import FleetRun
    from aeroexec.fleet.transport import free_endpoint

    try:
        spec = load_fleet(args.fleet_file)
        catalog = chosen_catalog(args.catalog)
        missions = {d.name: load_mission(d.mission, catalog) for d in spec.flown}
        world = load_world(spec.world) if spec.world else default_world()
    except FleetFileError as error:
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 1
    except (RunError, MissionFileError, WorldError) as error:
        print(error, file=sys.stderr)
        return 1
    for problem in spec.problems:
        print(problem, file=sys.stderr)
    if not spec.flown:
        print(f"{spec.file}: no drone has a mission: nothing flies here (run --router for a fleet flown elsewhere)",
              file=sys.stderr)
        return 1
    token = spec.token or os.environ.get(TOKEN_VARIABLE) or secrets.token_hex(16)
    folder = make_output_folder(args.output)
    if args.connect:
        membership = members.connect(spec, list(args.connect))
    else:
        membership = members.listen(spec, args.listen or [free_endpoint("tls")], folder)
    endpoints = membership.endpoints
    try:
        write_fleet_file(folder, spec.name, endpoints, token, membership.operator)
        elsewhere = [d.name for d in spec.drones if d.mission is None]
        print(f"fleet {spec.name}: {len(spec.flown)} drones here" + (f", {', '.join(elsewhere)} elsewhere"
                                                                     if elsewhere else "")
              + f", link on {', '.join(endpoints)}; token, endpoint and operator credentials in "
                f"{folder / FLEET_FILE}", file=sys.stderr, flush=True)
        node = membership.node(token)
        live = live_view_wanted(args)  # a person at a terminal: paced at real time unless --speed says
        watched = live or web.wanted(args)  # in a browser too; questions then wait for an answer
        fleet = FleetRun(node, list(spec.flown), missions, world=world, catalog=catalog,
                         speed=args.speed or (1.0 if watched else None), output=folder,
                         telemetry_rate=spec.telemetry_rate,
                         operator=remote_operator if web.wanted(args) else None)
        view = None
        browser = web.serve_console(args, fleet.engines, world,
                                    {d.name: d.mission for d in spec.flown if str(d.mission).endswith(".py")})
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
        membership.close()
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
