"""``aeroexec report LOG``: a flight report from an event log: ``path.png`` (the path over the world, outbound and
return legs, where each behavior started and ended), ``flight.png`` (altitude, speed and battery over time with
the behaviors shaded and the flight state changes), ``timeline.png`` (behaviors and beliefs over time) and
``report.html`` (a one-page summary with the images), next to the log unless ``--output DIR`` says otherwise."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from aeroexec.flight.journal import read_records
from aeroexec.flight.summary import summarize


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", help="an event log (events.jsonl in a run's output folder), or a run's journal "
                                    "(journal.sqlite)")
    parser.add_argument("--world", metavar="FILE",
                        help="the world flown in (default: the one the log names, else the built-in one)")
    parser.add_argument("--output", metavar="DIR", help="where the report goes (default: the log's folder)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.cli.reporting.html import write_html
    from aeroexec.cli.reporting.render import draw_flight, draw_path, draw_timeline

    log = Path(args.log)
    try:
        records = read_records(log)
    except (OSError, UnicodeDecodeError, ValueError) as error:
        print(f"{log}: cannot read the event log: {error}", file=sys.stderr)
        return 1
    if not records:
        print(f"{log}: the event log is empty", file=sys.stderr)
        return 1
    summary = summarize(records)
    world = load_world_for(args.world or summary.meta.get("world"))
    if isinstance(world, str):
        print(world, file=sys.stderr)
        return 1
    folder = Path(args.output) if args.output else log.parent
    folder.mkdir(parents=True, exist_ok=True)
    images = {"Path flown": draw_path(summary, world, folder / "path.png"),
              "Altitude, speed and battery": draw_flight(summary, folder / "flight.png"),
              "Timeline": draw_timeline(summary, folder / "timeline.png")}
    page = write_html(summary, images, folder / "report.html")
    for written in (*images.values(), page):
        print(written)
    print(f"{summary.meta.get('mission', 'mission')}: {summary.outcome}, {summary.duration:.1f} s, "
          f"{summary.distance:.1f} m flown, {len(summary.failures)} failures", file=sys.stderr)
    return 0


def load_world_for(name: str | None) -> Any:
    """The world of the report (the built-in one without a name); a message (str) when it cannot be loaded."""
    from aeroexec.drones.sim import WorldError, default_world, load_world

    try:
        return load_world(name) if name else default_world()
    except (WorldError, OSError) as error:
        return f"--world {name}: {error}"
