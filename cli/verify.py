"""``aeroexec verify MISSION``: every problem of a mission found without flying, with file:line; exit 1 on errors."""

from __future__ import annotations

import argparse
from pathlib import Path

from aeroexec.cli import robots
from aeroexec.cli.mission_files import MissionFileError, check_mission


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("missions", nargs="+", metavar="MISSION",
                        help="Python missions (.py) or behavior trees (.xml, .yaml, .yml)")
    parser.add_argument("--catalog", metavar="FILE", help="the behavior catalog (default: the robot kind's)")
    robots.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    try:
        catalog = robots.chosen(args).catalog(args.catalog)
    except robots.RobotKindError as error:
        print(error)
        return 2
    failed = False
    for name in args.missions:
        try:
            checked = check_mission(Path(name), catalog)
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
