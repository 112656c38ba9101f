"""Start-up of the ``aeroexec`` command: CPU time and peak memory of ``--help``, ``verify`` and an empty run, each
as a ratio to ``python -c pass`` measured in the same run.

Run ``python bench/startup.py`` (``--repeat N``, 7 by default; ``--readme`` rewrites docs/performance.md's table
with what it measured, between its ``startup-table`` markers: the table is regenerated, never edited by hand).
The commands run interleaved (one of each per round, so a machine whose load changes slows them alike), each after
a warm-up run, with bytecode caching on as an installed package runs (``PYTHONDONTWRITEBYTECODE`` removed). A
process's CPU time (user + system) is what a command costs; its wall time also counts the other processes that
took the cores meanwhile. Where the time goes: ``python -X importtime -m aeroexec.cli.main verify ...``.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from provenance import load as load_average
from provenance import measured_at

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "docs" / "performance.md"  # the tables moved there from README.md
AEROEXEC = [sys.executable, "-m", "aeroexec.cli.main"]
#: name, arguments, the most it may cost as a multiple of `python -c pass` (issue 36)
COMMANDS = (("aeroexec --help", ["--help"], 3.0),
            ("aeroexec verify missions/figure10.xml", ["verify", str(ROOT / "missions" / "figure10.xml")], 10.0),
            ("an empty run: aeroexec run missions/figure10.py --plain --max-time 0",
             ["run", str(ROOT / "missions" / "figure10.py"), "--plain", "--max-time", "0", "--output", "out"], 12.0))
BEGIN, END = "<!-- startup-table: begin (python bench/startup.py --readme) -->", "<!-- startup-table: end -->"


def once(command: list[str], cwd: str) -> tuple[float, float, float]:
    """(CPU seconds, wall seconds, peak RSS in MB) of one run of ``command``."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    began = time.perf_counter()
    process = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - began
    process.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_utime + usage.ru_stime, wall, usage.ru_maxrss / 1024


def measure(repeat: int) -> dict[str, list[tuple[float, float, float]]]:
    """Every command ``repeat`` times, interleaved, after one warm-up run of each."""
    runs = {"python -c pass": [sys.executable, "-c", "pass"], **{name: AEROEXEC + args for name, args, _ in COMMANDS}}
    results: dict[str, list[tuple[float, float, float]]] = {name: [] for name in runs}
    with tempfile.TemporaryDirectory() as cwd:
        for command in runs.values():
            once(command, cwd)  # bytecode written, files in the page cache
        for _ in range(repeat):
            for name, command in runs.items():
                results[name].append(once(command, cwd))
    return results


def table(results: dict[str, list[tuple[float, float, float]]], load: float) -> str:
    """The start-up table: median CPU, its ratio to the baseline, the goal, peak memory."""
    base = statistics.median(cpu for cpu, _, _ in results["python -c pass"])
    rows = ["| command | CPU (median) | ratio to `python -c pass` | goal | peak memory |",
            "|---|---:|---:|---:|---:|",
            f"| `python -c pass` (the baseline) | {base * 1000:.0f} ms | 1× | | "
            f"{statistics.median(m for _, _, m in results['python -c pass']):.0f} MB |"]
    for name, _, goal in COMMANDS:
        cpu = statistics.median(c for c, _, _ in results[name])
        memory = statistics.median(m for _, _, m in results[name])
        ratio = cpu / base
        verdict = "met" if ratio <= goal else f"MISSED ({ratio / goal:.1f}× the goal)"
        label = name.replace("an empty run: ", "")
        label = f"`{label}`" + (" (an empty run: start-up only)" if name.startswith("an empty run") else "")
        rows.append(f"| {label} | {cpu * 1000:.0f} ms | {ratio:.1f}× | ≤ {goal:g}×: {verdict} | {memory:.0f} MB |")
    repeat = len(results["python -c pass"])
    rows.append(f"\nMeasured by `python bench/startup.py --readme` ({repeat} interleaved runs of each, Python "
                f"{sys.version_info.major}.{sys.version_info.minor}) at {measured_at(load)}.")
    return "\n".join(rows)


def write_readme(text: str) -> None:
    readme = README.read_text(encoding="utf-8")
    pattern = re.compile(re.escape(BEGIN) + r".*?" + re.escape(END), re.S)
    if not pattern.search(readme):
        raise SystemExit(f"{README}: no start-up table between {BEGIN!r} and {END!r}")
    README.write_text(pattern.sub(lambda _: f"{BEGIN}\n{text}\n{END}", readme), encoding="utf-8")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs of each command (default 7)")
    parser.add_argument("--readme", action="store_true", help="rewrite the README's start-up table with the result")
    args = parser.parse_args()
    load = load_average()
    results = measure(args.repeat)
    text = table(results, load)
    print(text)
    for name, runs in results.items():
        cpus = sorted(c for c, _, _ in runs)
        walls = sorted(w for _, w, _ in runs)
        print(f"  {name}: CPU {cpus[0] * 1000:.0f}-{cpus[-1] * 1000:.0f} ms, wall median "
              f"{statistics.median(walls) * 1000:.0f} ms", file=sys.stderr)
    if args.readme:
        write_readme(text)
        print(f"{README}: start-up table rewritten", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
