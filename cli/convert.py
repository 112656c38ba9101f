"""``aeroexec convert MISSION --to xml``: a mission tree (a QGroundControl plan, YAML or XML) as BehaviorTree.CPP v4
XML for Groot2 and BehaviorTree.CPP, after the same checks as ``verify``; nothing is written when one fails."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from aeroexec.cli.lines import write_output
from aeroexec.flight.missions import MissionFileError, check_mission, is_plan, is_tree, world_home
from aeroexec.flight.robot import chosen_catalog
from aeroexec.trees.loaders.xml_writer import write_xml


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("mission", help="a QGroundControl plan (.plan) or a behavior tree (.xml, .yaml, .yml)")
    parser.add_argument("--to", choices=["xml"], default="xml", help="the format to write (BehaviorTree.CPP v4 XML)")
    parser.add_argument("-o", "--output", metavar="FILE", help="where to write it (default: standard output)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("--world", metavar="FILE", help="the world whose home point places a plan's positions "
                                                        "(default: the built-in one)")


def run(args: argparse.Namespace) -> int:
    path = Path(args.mission)
    if not is_tree(path):
        print(f"{path}: only behavior-tree missions convert (.plan, .xml, .yaml, .yml)", file=sys.stderr)
        return 1
    catalog = chosen_catalog(args.catalog)
    try:
        checked = check_mission(path, catalog, home=world_home(args.world) if is_plan(path) else None)
    except MissionFileError as error:
        print(error, file=sys.stderr)
        return 1
    for problem in checked.problems:
        print(problem, file=sys.stderr)
    if checked.errors or checked.tree is None:
        count = len(checked.errors)
        print(f"{path}: {count} error{'s' if count != 1 else ''}; nothing written", file=sys.stderr)
        return 1
    if callable(getattr(checked.tree, "build", None)):  # a TML mission builds itself: events, consults...
        print(f"{path}: a TML mission does not convert: its events and variables have no BehaviorTree.CPP form",
              file=sys.stderr)
        return 1
    return write_output(write_xml(checked.tree, catalog), args.output, f"{path.name} as BehaviorTree.CPP v4 XML")
