"""``aeroexec verify MISSION``: every problem of a mission found without flying, with file:line; exit 1 on errors.

Literal destinations and paths are checked against a world too (its bounds, geofence and the obstacle clearance the
catalog's preconditions ask): ``--world FILE``; else a mission planned on a map (a plan, a waypoint file) gets an
open field around it, a mission in local meters the simulator's built-in world (``trees.mission_world``);
``--home LAT,LON[,ALT]`` puts that world's home there; ``--no-world`` skips it. The whole route is estimated too
(length, duration, battery at landing: ``trees.route``).
``--library module:attribute`` adds behavior implementations, so a catalog behavior with no implementation
is reported before flight; ``--rules FILE`` adds rules, so expressions over the predicates they derive verify.
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Container
from pathlib import Path

from aeroexec.drones import geodesy
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.catalog.contingencies import contingency_syntax
from aeroexec.engine.errors import UNSUPPORTED, Problem, unsupported_message
from aeroexec.engine.library import LibraryError, behavior_names
from aeroexec.engine.robots import robot_kind_hint
from aeroexec.flight.errors import FlightError
from aeroexec.flight.missions import MissionFileError, check_mission, fleet_safety_check, safety_check
from aeroexec.flight.robot import load_world, robot_choice, vehicle_config, with_rule_files
from aeroexec.trees import formats

from aeroexec.limits import InputError, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

def add_arguments(parser: argparse.ArgumentParser) -> None:
    missions = parser.add_argument("missions", nargs="+", metavar="MISSION",
                                   help=f"missions, each a Python program or a behavior tree in one of the formats "
                                        f"{formats.described()}")
    missions.completer = formats.complete_mission_files  # type: ignore[attr-defined]  # argcomplete
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the robot kind's)")
    parser.add_argument("--robot", default="drone", metavar="KIND",
                        help="the kind of robot: drone (default), or one an installed plugin adds, e.g. rover")
    world = parser.add_mutually_exclusive_group()
    world.add_argument("--world", metavar="FILE",
                       help="check destinations and paths against this world, and place plans and waypoint files "
                            "at its home (default: an open field around a plan, else the simulator's)")
    world.add_argument("--no-world", action="store_true", help="do not check against any world")
    add_home_argument(parser)
    add_vehicle_argument(parser)
    add_library_arguments(parser)
    add_safety_rules_argument(parser)
    parser.add_argument("--strict-btcpp", action="store_true",
                        help="also an error: every construct BehaviorTree.CPP/Groot2 would refuse or read otherwise")


def add_safety_rules_argument(parser: argparse.ArgumentParser) -> None:
    """``--safety-rules FILE``: safety rules to watch besides the catalog's and the mission's (run and verify)."""
    parser.add_argument("--safety-rules", action="append", default=[], metavar="FILE",
                        help="safety rules (YAML) to check before flight and watch in flight, besides the catalog's "
                             f"and the mission's own (repeatable); a rule's contingency is one of: "
                             f"{contingency_syntax()}")


def parse_home(text: str) -> tuple[float, float, float | None]:
    """``--home LAT,LON[,ALT]`` (degrees, meters AMSL); the altitude is None when not given."""
    try:
        return geodesy.parse_home(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def add_home_argument(parser: argparse.ArgumentParser) -> None:
    """``--home LAT,LON[,ALT]``: where the world's home (the take-off point) is (run, verify, fleet, convert)."""
    parser.add_argument("--home", type=parse_home, metavar="LAT,LON[,ALT]",
                        help="the world's home (the take-off point): latitude, longitude and altitude AMSL "
                             "(default: the mission's home for a plan or waypoint file, else the world's)")


def add_vehicle_argument(parser: argparse.ArgumentParser) -> None:
    """``--vehicle FILE``: the vehicle's profile (endurance, speeds, rates, ceiling) (run, verify)."""
    parser.add_argument("--vehicle", metavar="FILE",
                        help="the vehicle's profile (YAML: endurance in minutes of hover, cruise_speed, max_speed, "
                             "climb_rate, max_climb_rate, descent_rate, ceiling...; docs/vehicles.md): the route's "
                             "battery check, the simulator and the safety rules use its figures (default: the "
                             "simulated multicopter's, 20 min of hover)")


def add_library_arguments(parser: argparse.ArgumentParser) -> None:
    """``--library`` and ``--processes``: plugins named ``module:attribute`` (run and verify)."""
    parser.add_argument("--library", action="append", default=[], metavar="MODULE:ATTR",
                        help="behavior implementations to add: a BehaviorLibrary, BehaviorProcess classes or a "
                             "callable returning either (repeatable; installed aeroexec.behaviors entry points "
                             "are always added)")
    parser.add_argument("--processes", action="append", default=[], metavar="MODULE:ATTR",
                        help="capability processes to add: a ProcessRegistry or a mapping of names to factories "
                             "(repeatable)")
    parser.add_argument("--rules", action="append", default=[], metavar="FILE",
                        help="rules deriving beliefs (head :- body.), and facts, added to the catalog's "
                             "(repeatable)")


def run(args: argparse.Namespace) -> int:
    try:
        choice = robot_choice(args.robot)
        catalog = choice.catalog(args.catalog)
    except FlightError as error:
        print(error)
        return 2
    try:  # the robot kind's world unless one is given (a world file that cannot be read is said once)
        world = None if args.no_world else load_world(choice.world_file(args.world), home=args.home)
        library = choice.library()  # a robot kind's own behaviors; None: the aerial library and plugins
        served = library.names() if library is not None else behavior_names(args.library)
        catalog = with_rule_files(catalog, args.rules)
        vehicle = vehicle_config(args.vehicle)
    except (FlightError, LibraryError) as error:
        print(error)
        return 1
    failed = False
    for name in args.missions:
        fleet = fleet_safety_check(Path(name), catalog, args.safety_rules,
                                   None if args.no_world else load_world(choice.world_file(args.world)))
        if fleet is not None:  # a fleet file: its drones' routes flown together against the separation rules
            for problem in fleet:
                print(problem)
            errors = sum(p.severity == "error" for p in fleet)
            print(f"{name}: {errors} error{'s' if errors != 1 else ''}; {'will not fly' if errors else 'ready to fly'}")
            failed = failed or errors > 0
            continue
        try:  # each mission in its own world: a plan's open field, at --home when given
            world = None if args.no_world else load_world(choice.world_file(args.world), mission=Path(name),
                                                           home=args.home)
            checked = check_mission(Path(name), catalog, world, vehicle=vehicle)
        except (MissionFileError, FlightError) as error:
            print(error)
            failed = True
            continue
        checked.problems += unimplemented(catalog, served, Path(name))
        checked.problems += safety_check(checked, catalog, args.safety_rules,
                                         VehicleModel(vehicle) if vehicle is not None else None)[1]
        if args.strict_btcpp and checked.tree is not None:
            from aeroexec.trees.portability import portability_problems  # here: only --strict-btcpp needs it

            checked.problems += portability_problems(checked.tree, catalog)
        elif args.strict_btcpp:  # said, not silently accepted: there is no tree to hold to BT.CPP's rules
            checked.problems.append(Problem("warning", "--strict-btcpp checks behavior trees against "
                                            "BehaviorTree.CPP and Groot2; a Python mission has no tree to check",
                                            name, 0))
        for problem in checked.problems:
            print(problem)
        if hint := robot_kind_hint(p.message for p in checked.problems):  # a rover's mission without --robot
            print(f"{name}: hint: {hint}")
        if checked.route is not None and checked.route.length > 0:
            print(f"{name}: {checked.route.summary()}")
        errors, warnings = len(checked.errors), len(checked.problems) - len(checked.errors)
        verb = "fly" if choice.kind is None else "run"  # a rover does not fly
        verdict = f"ready to {verb}" if not errors else f"will not {verb}"
        against = f" (checked against the world {world.name})" if world is not None and not errors else ""
        print(f"{name}: {errors} error{'s' if errors != 1 else ''}, {warnings} warning{'s' if warnings != 1 else ''}"
              f"; {verdict}{against}")
        failed = failed or errors > 0
    return 1 if failed else 0


def unimplemented(catalog: Any, served: Container[str], path: Path) -> list[Problem]:
    """A warning for each behavior the mission names that the catalog has and no implementation serves (``served``:
    the names the behavior library serves)."""
    try:
        text = read_text(path, what="the mission")  # the guarded read: a FIFO or a device is never opened
    except InputError:
        return []  # the mission's own check has said why it cannot be read
    return [Problem("warning", f"{UNSUPPORTED}: {unsupported_message(name)}", str(path), 0)
            for name in sorted(catalog.behaviors) if name not in served and re.search(rf"\b{name}\b", text)]
