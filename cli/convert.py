"""``aeroexec convert MISSION --to xml|plan|waypoints``: a mission tree (a plan, a waypoint file, YAML or XML) as
BehaviorTree.CPP v4 XML for Groot2 and BehaviorTree.CPP, or, when it is a sequence of mission items, as a
QGroundControl ``.plan`` or a Mission Planner ``.waypoints`` file; after the same checks as ``verify`` (the same
world, the same route), nothing is written when one fails."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from aeroexec.cli.lines import write_output
from aeroexec.cli.verify import add_home_argument
from aeroexec.flight.missions import MissionFileError, check_mission, is_tree
from aeroexec.flight.robot import chosen_catalog, load_world
from aeroexec.flight.spec import FlightError
from aeroexec.trees.items import PlanDocument
from aeroexec.trees.items.writer import WriteError, write_plan, write_waypoints
from aeroexec.trees.loaders.xml_writer import write_xml

FORMATS = {"xml": "BehaviorTree.CPP v4 XML", "plan": "a QGroundControl plan", "waypoints": "a QGC WPL 110 file"}
SUFFIXES = {".xml": "xml", ".plan": "plan", ".waypoints": "waypoints", ".txt": "waypoints"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("mission", help="a mission tree: a plan (.plan, .mission), a waypoint file (.waypoints, "
                                        ".txt) or a behavior tree (.xml, .yaml, .yml)")
    parser.add_argument("--to", choices=list(FORMATS), help="the format to write: xml (BehaviorTree.CPP v4), plan "
                                                            "(QGroundControl) or waypoints (QGC WPL 110; Mission "
                                                            "Planner); default: -o's extension, else xml")
    parser.add_argument("-o", "--output", metavar="FILE", help="where to write it (default: standard output)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    world = parser.add_mutually_exclusive_group()
    world.add_argument("--world", metavar="FILE", help="the world the mission is checked against, whose home places "
                                                       "local meters (default: as verify chooses it)")
    world.add_argument("--no-world", action="store_true", help="do not check against any world")
    add_home_argument(parser)


def run(args: argparse.Namespace) -> int:
    path = Path(args.mission)
    if not is_tree(path):
        print(f"{path}: only behavior-tree missions convert (.plan, .mission, .waypoints, .txt, .xml, .yaml, .yml)",
              file=sys.stderr)
        return 1
    target = args.to or SUFFIXES.get(Path(args.output).suffix.lower() if args.output else "", "xml")
    catalog = chosen_catalog(args.catalog)
    try:
        world = None if args.no_world else load_world(args.world, mission=path, home=args.home)
        checked = check_mission(path, catalog, world, home=world.home if world is not None else None)
    except (MissionFileError, FlightError) as error:
        print(error, file=sys.stderr)
        return 1
    for problem in checked.problems:
        print(problem, file=sys.stderr)
    if checked.errors or checked.tree is None:
        count = len(checked.errors)
        print(f"{path}: {count} error{'s' if count != 1 else ''}; nothing written", file=sys.stderr)
        return 1
    tree = checked.tree
    if callable(getattr(tree, "build", None)):  # a TML mission builds itself: events, consults...
        print(f"{path}: a TML mission does not convert: its events and variables have no BehaviorTree.CPP form",
              file=sys.stderr)
        return 1
    if target == "xml":
        text = write_xml(tree, catalog)
    else:
        home = tree.home if isinstance(tree, PlanDocument) and tree.home else getattr(world, "home", None)
        if home is None:
            print(f"{path}: a plan needs a home: give --home LAT,LON[,ALT] or --world FILE", file=sys.stderr)
            return 1
        try:
            text = (write_plan if target == "plan" else write_waypoints)(tree, home)
        except WriteError as error:
            for file, line, message in error.problems:
                print(f"{file}:{line}: error: {message}", file=sys.stderr)
            print(f"{path}: {len(error.problems)} node{'s' if len(error.problems) != 1 else ''} without a mission "
                  f"item; nothing written", file=sys.stderr)
            return 1
    return write_output(text, args.output, f"{path.name} as {FORMATS[target]}")
