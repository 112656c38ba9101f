"""``aeroexec convert MISSION --to xml|plan|waypoints``: a mission tree of any tree format of the table
(:mod:`aeroexec.trees.formats`) written in a format the table can write: BehaviorTree.CPP v4 XML for Groot2 and
BehaviorTree.CPP, or, when it is a sequence of mission items, a QGroundControl ``.plan`` or a Mission Planner
``.waypoints`` file; after the same checks as ``verify`` (the same world, the same route), nothing is written when
one fails."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from aeroexec.cli.lines import write_output
from aeroexec.cli.verify import add_home_argument
from aeroexec.flight.missions import MissionFileError, check_mission, is_tree
from aeroexec.flight.robot import chosen_catalog, load_world
from aeroexec.flight.spec import FlightError
from aeroexec.trees import formats
from aeroexec.trees.items import PlanDocument
from aeroexec.trees.items.writer import WriteError

#: What ``--to`` writes: its word -> what the format is (the table's formats that can be written)
FORMATS = {word: fmt.summary for word, fmt in formats.writable().items()}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    mission = parser.add_argument("mission", help=f"a mission tree, in one of the formats "
                                                  f"{formats.described(tree=True)}")
    mission.completer = formats.complete_mission_files  # type: ignore[attr-defined]  # argcomplete
    written = ", ".join(f"{word} ({summary})" for word, summary in FORMATS.items())
    parser.add_argument("--to", choices=list(FORMATS), help=f"the format to write: {written}; default: -o's "
                                                            f"extension, else xml")
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
        print(f"{path}: only behavior-tree missions convert: {formats.expected(tree=True)}", file=sys.stderr)
        return 1
    named = formats.format_of(args.output) if args.output else None  # -o's extension
    target = args.to or (named.writes_as if named is not None and named.writes_as in FORMATS else "xml")
    written = formats.writable()[target]
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
    home = tree.home if isinstance(tree, PlanDocument) and tree.home else getattr(world, "home", None)
    if written.items and home is None:
        print(f"{path}: a plan needs a home: give --home LAT,LON[,ALT] or --world FILE", file=sys.stderr)
        return 1
    try:
        text = written.writer()(tree, catalog, home)
    except WriteError as error:
        for file, line, message in error.problems:
            print(f"{file}:{line}: error: {message}", file=sys.stderr)
        print(f"{path}: {len(error.problems)} node{'s' if len(error.problems) != 1 else ''} without a mission "
              f"item; nothing written", file=sys.stderr)
        return 1
    return write_output(text, args.output, f"{path.name} as {FORMATS[target]}")
