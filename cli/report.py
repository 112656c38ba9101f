"""``aeroexec report RUN_DIR|LOG``: a flight report from a run's event log: ``path.png`` (the path over the world,
where behaviors started and ended), ``flight.png`` (altitude, speed and battery under the behaviors and flight
states), ``timeline.png`` (behaviors and beliefs over time) and ``report.html`` (the page a pilot reads: a header
with the outcome, date, version, mission, drone and seed, the images, outcomes and failures), next to the log
unless ``--output DIR`` says otherwise. Each step is named on stderr as it starts (drawing takes seconds;
matplotlib's first use builds its font cache)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from aeroexec.flight.flight_log import read_flight_log
from aeroexec.flight.summary import summarize

from aeroexec import __version__


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", metavar="RUN_DIR|LOG", help="a run's output folder or its event log")
    parser.add_argument("--world", metavar="FILE",
                        help="the world flown in (default: the one the log names, else the built-in one)")
    parser.add_argument("--output", metavar="DIR", help="where the report goes (default: the log's folder)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.flight.replay import ReplayError, find_log

    try:
        log = find_log(args.run_dir)
    except ReplayError as error:
        print(error, file=sys.stderr)
        return 1
    step(f"reading {log}")
    try:
        records = read_flight_log(log)
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
    step(f"{len(records):,} records; drawing with matplotlib")
    from aeroexec.cli.reporting.flight_chart import flight_figure
    from aeroexec.cli.reporting.html import Image, write_html
    from aeroexec.cli.reporting.path_map import path_figure
    from aeroexec.cli.reporting.style import save
    from aeroexec.cli.reporting.timeline import timeline_figure

    images = []
    for title, draw, name in (("Path flown", lambda: path_figure(summary, world), "path.png"),
                              ("Altitude, speed and battery", lambda: flight_figure(summary), "flight.png"),
                              ("Timeline", lambda: timeline_figure(summary), "timeline.png")):
        step(f"drawing {name}")
        images.append(Image(title, folder / name, save(draw(), folder / name)))
    page = write_html(summary, images, folder / "report.html", __version__, flown_at(summary.meta, log), log)
    for written in (*(image.png for image in images), page):
        print(written)
    failures = len(summary.failures)
    print(f"{summary.meta.get('mission', 'mission')}: {summary.outcome}, {summary.duration:.1f} s, "
          f"{summary.distance:.1f} m flown, {failures} failure{'' if failures == 1 else 's'}", file=sys.stderr)
    return 0


def flown_at(meta: dict[str, Any], log: Path) -> str:
    """When the run was flown: the log's wall-clock start, else (a simulated run's log carries no wall time, so
    replays stay identical) when the log was last written."""
    import datetime

    if meta.get("wall_time"):
        return str(meta["wall_time"]).replace("T", " ")
    written = datetime.datetime.fromtimestamp(log.stat().st_mtime).astimezone()
    return f"{written:%Y-%m-%d %H:%M:%S %Z} (end of the log)"


def step(what: str) -> None:
    """A step of the report, on stderr as it starts."""
    print(f"report: {what} ...", file=sys.stderr, flush=True)


def load_world_for(name: str | None) -> Any:
    """The world of the report (the built-in one without a name); a message (str) when it cannot be loaded."""
    from aeroexec.drones.sim import WorldError, default_world, load_world

    try:
        return load_world(name) if name else default_world()
    except (WorldError, OSError) as error:
        return f"--world {name}: {error}"
