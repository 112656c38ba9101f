"""``aeroexec campaign``: the simulation campaign of whole flights. Each case is drawn from its seed alone (a
mission, the operator's commands, faults, rules), flown in the simulator on its clock and judged by the
invariants every run must keep; each violation is printed with its invariant's name and the one command that
replays it (``aeroexec campaign --seed N``), which flies that case again with its files kept, and shrinks it.

    aeroexec campaign --flights 10000            # on every core; --dask or --scheduler ADDRESS for Dask
    aeroexec campaign --seed 1234                # one case again, its files in aeroexec_campaign/seed-1234
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from aeroexec.rehearsal.simulation import GATED

    parser.add_argument("--flights", type=int, default=300, metavar="N", help="how many cases (default 300)")
    parser.add_argument("--first", type=int, default=0, metavar="SEED",
                        help="the first case's seed (case i has seed FIRST + i)")
    parser.add_argument("--seed", type=int, metavar="N", help="fly the case of seed N again, keep its files and "
                                                              "shrink it if an invariant fails")
    parser.add_argument("--workers", type=int, default=None, metavar="N",
                        help="worker processes (default: one per core)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--dask", action="store_true", help="run on a Dask LocalCluster on this machine")
    where.add_argument("--scheduler", metavar="ADDRESS", help="run on the Dask scheduler at ADDRESS")
    parser.add_argument("--with", dest="extra", action="append", default=[], choices=sorted(GATED),
                        metavar="KIND", help="also draw a fault kind that finds a defect not fixed yet: "
                                             + ("; ".join(f"{k}: {v}" for k, v in GATED.items())
                                                or "none now, every kind is drawn"))
    parser.add_argument("--outcomes", metavar="FILE",
                        help="write each case's outcome to FILE as JSON lines (seed, how it ended, parts, the "
                             "invariants it violated), in the order of the seeds: two runs compared seed by seed")
    parser.add_argument("--output", metavar="DIR", default="aeroexec_campaign",
                        help="where a replayed case's files go (default aeroexec_campaign)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.rehearsal.simulation import draw, figures, judge, replay_command, run_campaign, shrink
    from aeroexec.rehearsal.simulation.running import Interrupted

    extra = tuple(sorted(set(args.extra)))
    if args.seed is not None:
        case = draw(args.seed, frozenset(extra))
        keep = Path(args.output) / f"seed-{args.seed}"
        result = judge(case, keep, extra)
        result.extra = extra
        print(case.describe())
        print(f"ended {result.ended} in {result.parts} part{'s' if result.parts != 1 else ''}; files in {keep}")
        if not result.violations:
            print("every invariant held")
            return 0
        for violation in result.violations:
            print(f"violated {violation}")
        smaller = shrink(case, result.violations[0].invariant, extra=extra)
        if smaller.dropped:
            print(f"still violated by the smaller case:\n{smaller.describe()}")
        return 1
    if args.flights < 1:
        print("--flights must be at least 1", file=sys.stderr)
        return 2
    seeds = range(args.first, args.first + args.flights)
    done, failed = [0], [0]
    try:
        outcomes = open(args.outcomes, "w", encoding="utf-8") if args.outcomes else None  # noqa: SIM115
    except OSError as error:
        print(f"--outcomes {args.outcomes}: {error.strerror}", file=sys.stderr)
        return 2
    began = time.perf_counter()

    def progress(result) -> None:  # noqa: ANN001
        done[0] += 1
        failed[0] += result.failed
        if result.violations:
            print(result.report(), flush=True)
        if outcomes is not None:
            outcomes.write(result.outcome_line() + "\n")
            outcomes.flush()
        if done[0] % 250 == 0:
            wall = time.perf_counter() - began
            print(f"{done[0]} flights in {wall:.0f} s: {done[0] / wall * 60:.0f} flights per minute, "
                  f"{failed[0]} violation{'s' if failed[0] != 1 else ''}", file=sys.stderr, flush=True)

    interrupted = False
    try:
        results = run_campaign(seeds, extra, args.workers, args.scheduler, args.dask, progress)
    except Interrupted as interrupt:  # Ctrl-C: the figures of what was flown
        results, interrupted = interrupt.results, True
        print(f"interrupted after {len(results)} of {args.flights} flights", file=sys.stderr)
    finally:
        if outcomes is not None:
            outcomes.close()
    found = figures(results, time.perf_counter() - began)
    ended = ", ".join(f"{n} {word}" for word, n in sorted(found.ended.items(), key=lambda item: -item[1]))
    print(f"{found.flights} flights in {found.wall:.1f} s: {found.per_minute:.0f} flights per minute; {ended}")
    if found.failed:
        by = ", ".join(f"{name} {n}" for name, n in sorted(found.by_invariant.items()))
        print(f"{found.failed} violation{'s' if found.failed != 1 else ''} ({by}); replay one with "
              f"{replay_command(next(r.seed for r in results if r.failed), extra)}")
        return 1
    print("0 violations")
    return 130 if interrupted else 0
