"""``aeroexec verify MISSION``: every problem of a mission found without flying, with file:line; exit 1 on errors."""

from __future__ import annotations

import argparse
from pathlib import Path

from aeroexec.cli.catalog import chosen_catalog
from aeroexec.cli.mission_files import MissionFileError, check_mission
from aeroexec.trees.portability import portability_problems


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("missions", nargs="+", metavar="MISSION",
                        help="Python missions (.py) or behavior trees (.xml, .yaml, .yml)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("--strict-btcpp", action="store_true",
                        help="also an error: every construct BehaviorTree.CPP/Groot2 would refuse or read otherwise")


def run(args: argparse.Namespace) -> int:
    catalog = chosen_catalog(args.catalog)
    failed = False
    for name in args.missions:
        try:
            checked = check_mission(Path(name), catalog)
        except MissionFileError as error:
            print(error)
            failed = True
            continue
        if args.strict_btcpp and checked.tree is not None:
            checked.problems += portability_problems(checked.tree, catalog)
        for problem in checked.problems:
            print(problem)
        errors, warnings = len(checked.errors), len(checked.problems) - len(checked.errors)
        verdict = "ready to fly" if not errors else "will not fly"
        print(f"{name}: {errors} error{'s' if errors != 1 else ''}, {warnings} warning{'s' if warnings != 1 else ''}"
              f"; {verdict}")
        failed = failed or errors > 0
    return 1 if failed else 0
