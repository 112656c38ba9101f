"""Rehearsal throughput: simulated seconds flown per wall second per core, and per CPU second of the workers,
for a campaign of ``--runs`` runs of a mission in worker processes on every core (``aeroexec rehearse``).

Run ``python bench/rehearsal.py [--mission missions/iarc7.xml] [--runs 20]``."""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from aeroexec.rehearsal import fly_local, seeds

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--mission", default=str(ROOT / "missions" / "iarc7.xml"))
    parser.add_argument("--runs", type=int, default=20)
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    began = time.perf_counter()
    results = fly_local(args.mission, seeds(args.runs), workers=cores)
    wall = time.perf_counter() - began
    simulated = sum(r.duration for r in results)
    cpu = sum(r.wall for r in results)
    name = Path(args.mission).name
    print(f"{args.runs} runs of {name} on {cores} cores: {simulated:.0f} simulated s in {wall:.1f} s")
    print(f"  simulated s per wall s per core   {simulated / wall / cores:8.1f}")
    print(f"  simulated s per CPU s (workers)   {simulated / max(cpu, 1e-9):8.1f}")
    print(f"  workers' CPU s per wall s         {cpu / wall:8.2f}  ({len({r.worker for r in results})} worker "
          f"processes flew runs)")
    print(f"  load average                      {os.getloadavg()[0]:8.2f}")


if __name__ == "__main__":
    main()
