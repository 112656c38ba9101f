"""``aeroexec verify MISSION``: every problem of a mission found without flying, with file:line; exit 1 on errors."""

from __future__ import annotations

import argparse
from pathlib import Path

from aeroexec.cli.catalog import chosen_catalog
from aeroexec.cli.mission_files import MissionFileError, check_mission, is_plan, world_home


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("missions", nargs="+", metavar="MISSION",
                        help="Python missions (.py), behavior trees (.xml, .yaml, .yml) or QGroundControl "
                             "plans (.plan)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the aerial one)")
    parser.add_argument("--world", metavar="FILE", help="the world whose home point places QGroundControl plans "
                                                        "(default: the built-in one)")


def run(args: argparse.Namespace) -> int:
    catalog = chosen_catalog(args.catalog)
    failed = False
    for name in args.missions:
        try:
            path = Path(name)
            checked = check_mission(path, catalog, world_home(args.world) if is_plan(path) else None)
        except MissionFileError as error:
            print(error)
            failed = True
            continue
        for problem in checked.problems:
            print(problem)
        errors, warnings = len(checked.errors), len(checked.problems) - len(checked.errors)
        verdict = "ready to fly" if not errors else "will not fly"
        print(f"{name}: {errors} error{'s' if errors != 1 else ''}, {warnings} warning{'s' if warnings != 1 else ''}"
              f"; {verdict}")
        failed = failed or errors > 0
    return 1 if failed else 0
