"""``aeroexec rehearse MISSION [--runs N]``: the mission flown N times in the simulator with variations (wind,
battery capacity and drain, sensor noise, marker detection, a link drop), in worker processes on every core or on
a Dask cluster (``--dask``: a local cluster; ``--scheduler ADDRESS``: an existing one); the success rate, the worst
runs and an HTML report. ``--replay SEED`` flies one run again, its files kept."""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from aeroexec.cli.verify import add_safety_rules_argument


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("mission", metavar="MISSION", help="the mission to rehearse")
    parser.add_argument("--runs", type=int, default=20, metavar="N", help="how many runs (default 20)")
    parser.add_argument("--seed", type=int, default=0, help="the first run's seed (run i has seed + i)")
    parser.add_argument("--workers", type=int, default=None, metavar="N",
                        help="worker processes (default: one per core)")
    parser.add_argument("--max-time", type=float, default=900.0, metavar="S", help="simulated seconds a run may take")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--dask", action="store_true", help="run on a Dask LocalCluster on this machine")
    where.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask scheduler at ADDRESS")
    parser.add_argument("--replay", type=int, metavar="SEED", help="fly the run of SEED again, keeping its files")
    parser.add_argument("--output", metavar="DIR", default="aeroexec_rehearsal", help="where the report goes")
    add_safety_rules_argument(parser)


def run(args: argparse.Namespace) -> int:
    from aeroexec.rehearsal import fly, fly_dask, fly_local, seeds, summary, write_report

    mission = str(Path(args.mission))
    if not Path(mission).is_file():
        print(f"{mission}: no such mission file")
        return 1
    if args.runs < 1:
        print("--runs must be at least 1")
        return 2
    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    if args.replay is not None:
        result = fly(mission, args.replay, tuple(args.safety_rules), args.max_time, str(output / f"run-{args.replay}"))
        print(f"run {args.replay}: {result.status} at t={result.duration:.1f} s, battery {result.battery:.1f} %, "
              f"wind {result.variation.wind_speed:.1f} m/s; files in {output / f'run-{args.replay}'}")
        return 0 if result.success else 1
    run_seeds = seeds(args.runs, args.seed)
    workers = args.workers or os.cpu_count() or 1
    began = time.perf_counter()
    if args.dask or args.scheduler:
        results = fly_dask(mission, run_seeds, tuple(args.safety_rules), args.scheduler, workers, args.max_time)
        engine = f"Dask ({args.scheduler or f'a LocalCluster of {workers} workers'})"
    else:
        results = fly_local(mission, run_seeds, tuple(args.safety_rules), workers, args.max_time)
        engine = f"{workers} worker processes"
    wall = time.perf_counter() - began
    figures = summary(results)
    simulated = sum(r.duration for r in results)
    cpu = sum(r.wall for r in results)
    report = write_report(results, mission, output / "rehearsal.html", engine)
    print(f"{mission}: {figures['successes']} of {figures['runs']} runs completed ({100 * figures['rate']:.0f} %) "
          f"on {engine} in {wall:.1f} s ({len({r.worker for r in results})} flew runs, {cpu / wall:.1f} CPU s per "
          f"wall s; {simulated / max(cpu, 1e-9):.0f} simulated s per CPU s)")
    for name, count in sorted(figures["fired"].items()):
        print(f"  safety rule {name} fired in {count} run{'s' if count != 1 else ''}")
    print("  worst runs:")
    for r in figures["worst"]:
        print(f"    seed {r.variation.seed}: {r.status}, {r.duration:.1f} s, battery {r.battery:.1f} %, wind "
              f"{r.variation.wind_speed:.1f} m/s  (aeroexec rehearse {mission} --replay {r.variation.seed})")
    print(f"  report: {report}")
    return 0
