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

from aeroexec.flight.journal import read_records
from aeroexec.flight.summary import summarize

from aeroexec import __version__


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", metavar="RUN_DIR|LOG",
                        help="a run's output folder, its event log or its journal (journal.sqlite)")
    parser.add_argument("--world", metavar="FILE",
                        help="the world flown in (default: the one the log names or describes, else the built-in "
                             "one)")
    parser.add_argument("--output", metavar="DIR", help="where the report goes (default: the log's folder)")
    parser.add_argument("--autopilot-log", metavar="FILE", type=Path,
                        help="the autopilot's own log of the flight (PX4 .ulg, ArduPilot DataFlash .bin): drawn "
                             "on the mission's clock, its estimate and setpoints beside the behaviors")


def run(args: argparse.Namespace) -> int:
    from aeroexec.flight.replay import ReplayError, find_log

    try:
        log = find_log(args.run_dir)
    except ReplayError as error:
        print(error, file=sys.stderr)
        return 1
    step(f"reading {log}")
    try:
        records = read_records(log)
    except (OSError, UnicodeDecodeError, ValueError) as error:
        print(f"{log}: cannot read the event log: {error}", file=sys.stderr)
        return 1
    if not records:
        print(f"{log}: the event log is empty", file=sys.stderr)
        return 1
    summary = summarize(records)
    world = world_of_run(summary.meta, args.world)
    if isinstance(world, str):
        print(world, file=sys.stderr)
        return 1
    autopilot = _autopilot_log(args.autopilot_log, summary) if args.autopilot_log else None
    if isinstance(autopilot, str):
        print(autopilot, file=sys.stderr)
        return 1
    folder = Path(args.output) if args.output else log.parent
    folder.mkdir(parents=True, exist_ok=True)
    step(f"{len(records):,} records; drawing with matplotlib")
    from aeroexec.cli.reporting.flight_chart import flight_figure
    from aeroexec.cli.reporting.html import Image, write_html
    from aeroexec.cli.reporting.path_map import path_figure
    from aeroexec.cli.reporting.style import save
    from aeroexec.cli.reporting.timeline import timeline_figure

    drawings = [("Path flown", lambda: path_figure(summary, world), "path.png"),
                ("Altitude, speed and battery", lambda: flight_figure(summary), "flight.png"),
                ("Timeline", lambda: timeline_figure(summary), "timeline.png")]
    if autopilot is not None:
        from aeroexec.cli.reporting.autopilot_chart import autopilot_figure

        drawings.append(("The autopilot's log", lambda: autopilot_figure(summary, *autopilot), "autopilot.png"))
    images = []
    for title, draw, name in drawings:
        step(f"drawing {name}")
        images.append(Image(title, folder / name, save(draw(), folder / name)))
    page = write_html(summary, images, folder / "report.html", __version__, flown_at(summary.meta, log), log)
    for written in (*(image.png for image in images), page):
        print(written)
    failures = len(summary.failures)
    refused = sum(not c.taken for c in summary.changes)
    changed = f", {len(summary.changes)} mission changes ({refused} refused)" if summary.changes else ""
    print(f"{summary.meta.get('mission', 'mission')}: {summary.outcome}, {summary.duration:.1f} s, "
          f"{summary.distance:.1f} m flown, {failures} failure{'' if failures == 1 else 's'}{changed}",
          file=sys.stderr)
    return 0


def _autopilot_log(path: Path, summary: Any) -> tuple[Any, Any] | str:
    """The autopilot's log read and aligned with the run (printed), or why it cannot be."""
    from aeroexec.cli.reporting.autopilot_log import AutopilotLogError, align, read_autopilot_log

    step(f"reading the autopilot's log {path}")
    try:
        log = read_autopilot_log(path)
        alignment = align(log, summary)
    except AutopilotLogError as error:
        return str(error)
    print(f"{path}: {log.kind} of {log.system}: boot time = engine time + {alignment.offset:.3f} s "
          f"({alignment.rms:.2f} m RMS over {alignment.samples} positions)", file=sys.stderr)
    return log, alignment


def flown_at(meta: dict[str, Any], log: Path) -> str:
    """When the run was flown: the log's wall-clock start, else (a simulated run's log carries no wall time, so
    replays stay identical) when the log was last written."""
    import datetime

    if meta.get("wall_time"):
        return datetime.datetime.fromisoformat(str(meta["wall_time"])).isoformat(sep=" ", timespec="seconds")
    written = datetime.datetime.fromtimestamp(log.stat().st_mtime).astimezone()
    return f"{written:%Y-%m-%d %H:%M:%S %Z} (end of the log)"


def step(what: str) -> None:
    """A step of the report, on stderr as it starts."""
    print(f"report: {what} ...", file=sys.stderr, flush=True)


def world_of_run(meta: dict[str, Any], world_file: str | None = None) -> Any:
    """The world a run flew in, from its log's first record: ``world_file`` (``--world``) or the world file it
    names; else the field its ``home`` and ``bounds`` describe (a world generated around a mission planned on a
    map), the built-in world when they are the built-in world's; the built-in world for an older log of a
    simulated run; None (no world to draw) for a vehicle flown without one. A message (str) when the file
    cannot be loaded."""
    from aeroexec.drones.sim import WorldError, default_world, load_world
    from aeroexec.drones.sim.open_field import field_of

    name = world_file or meta.get("world")
    try:
        if name:
            return load_world(name)
        built_in = default_world()
        home, bounds = meta.get("home"), meta.get("bounds")
        if home and bounds:
            same = [list(built_in.bounds.lower), list(built_in.bounds.upper)] == [list(b) for b in bounds] and \
                all(abs(float(a) - float(b)) < 1e-6 for a, b in zip(home[:2], built_in.home[:2], strict=False))
            return built_in if same else field_of(home, bounds)
        return built_in if str(meta.get("drone", "sim")) == "sim" else None
    except (WorldError, OSError, TypeError, ValueError) as error:
        return f"{'--world ' if world_file else ''}{name or 'the log'}: {error}"
