"""Start-up of the ``aeroexec`` command: CPU time and peak memory of ``--help``, ``verify`` and an empty run, each
as a ratio to ``python -c pass`` of the same interpreter, measured in the same run.

The interpreter is the one a user gets from ``pip install .``: run from a checkout, the bench makes a virtualenv of
its own and installs the checkout into it, not editable (an editable install's ``__editable__`` finder runs at every
start of the interpreter, ``python -c pass`` included, and flatters every ratio). The virtualenv is kept in the
temporary folder (``aeroexec-bench-<user>/startup-venv-pyX.Y-<checkout>``: one per checkout, so two worktrees measured
at once never install over each other's) and installed again only when the checkout's files differ from what it
holds, so a second run starts at once; ``--python PATH`` measures another interpreter's installed ``aeroexec``
instead. The commands are the ones a user types: the virtualenv's ``aeroexec`` script.

Run ``python bench/startup.py`` (``--repeat N``, 7 by default; ``--docs`` rewrites the start-up table of
``docs/performance/run.md`` with what it measured, between its ``startup-table`` markers: the table is regenerated,
never edited by hand). The commands run interleaved (one of each per round, so a machine whose load changes slows
them alike), each after a warm-up run, with bytecode caching on as an installed package runs
(``PYTHONDONTWRITEBYTECODE`` removed). A process's CPU time (user + system) is what a command costs; its wall time
also counts the other processes that took the cores meanwhile. Where the time goes:
``VENV/bin/python -X importtime -m aeroexec.cli.main verify ...`` (it leaves out the modules imported through
``importlib.import_module``: aeroexec's lazy names, plugins, the aerial behaviors); every instruction, the same in
every run whatever the load: ``valgrind --tool=callgrind VENV/bin/aeroexec run ...``, against ``python -c pass``'s.
"""

from __future__ import annotations

import argparse
import getpass
import hashlib
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from provenance import load as load_average
from provenance import measured_at, write_section

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "performance" / "run.md"
#: what ``pip install .`` reads of the checkout (pyproject's package folders and the files it names)
SOURCES = ("aeroexec", "dialects", "grammar", "beliefs", "engine", "drones", "trees", "catalogs", "missions",
           "fleet", "flight", "cli", "console", "rehearsal", "pyproject.toml", "README.md", "LICENSE")
#: name, arguments, the most it may cost as a multiple of `python -c pass` (issue 45)
COMMANDS = (("aeroexec --help", ["--help"], 3.0),
            ("aeroexec verify missions/figure10.xml", ["verify", str(ROOT / "missions" / "figure10.xml")], 8.0),
            ("an empty run: aeroexec run missions/figure10.py --plain --max-time 0",
             ["run", str(ROOT / "missions" / "figure10.py"), "--plain", "--max-time", "0", "--output", "out"], 10.0))
BEGIN, END = "<!-- startup-table: begin (python bench/startup.py --docs) -->", "<!-- startup-table: end -->"


def fingerprint() -> str:
    """A hash of every file ``pip install .`` would install from the checkout, as they are now."""
    digest = hashlib.sha256()
    for name in SOURCES:
        path = ROOT / name
        files = [path] if path.is_file() else sorted(p for p in path.rglob("*")
                                                     if p.is_file() and "__pycache__" not in p.parts)
        for file in files:
            digest.update(str(file.relative_to(ROOT)).encode() + b"\0" + file.read_bytes() + b"\0")
    return digest.hexdigest()


def installed_venv(folder: Path) -> Path:
    """The interpreter of a virtualenv in ``folder`` holding the checkout installed as ``pip install .`` installs
    it (made, or installed again, only when the checkout changed since)."""
    python = folder / "bin" / "python"
    stamp, wanted = folder / "aeroexec-fingerprint", fingerprint()
    if python.exists() and stamp.exists() and stamp.read_text() == wanted:
        return python
    fresh = not python.exists()
    if fresh:
        print(f"making a virtualenv in {folder} (once)", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", str(folder)], check=True)
    with tempfile.TemporaryDirectory(prefix="aeroexec-bench-source-") as copy:
        # a copy of the checkout: setuptools' build/ folder in the checkout could hold modules deleted since
        for name in SOURCES:
            path = ROOT / name
            if path.is_file():
                shutil.copy2(path, Path(copy) / name)
            else:
                shutil.copytree(path, Path(copy) / name, ignore=shutil.ignore_patterns("__pycache__"))
        print(f"installing the checkout into {folder} (pip install .)", file=sys.stderr)
        subprocess.run([str(python), "-m", "pip", "install", "-q", *([] if fresh else ["--no-deps",
                        "--force-reinstall"]), copy], check=True, stdout=subprocess.DEVNULL)
    stamp.write_text(wanted)
    return python


def once(command: list[str], cwd: str) -> tuple[float, float, float]:
    """(CPU seconds, wall seconds, peak RSS in MB) of one run of ``command``."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPATH")}
    began = time.perf_counter()
    process = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - began
    process.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_utime + usage.ru_stime, wall, usage.ru_maxrss / 1024


def measure(python: Path, repeat: int) -> dict[str, list[tuple[float, float, float]]]:
    """Every command ``repeat`` times, interleaved, after one warm-up run of each."""
    script = python.parent / "aeroexec"
    aeroexec = [str(script)] if script.exists() else [str(python), "-m", "aeroexec.cli.main"]
    runs = {"python -c pass": [str(python), "-c", "pass"], **{name: aeroexec + args for name, args, _ in COMMANDS}}
    results: dict[str, list[tuple[float, float, float]]] = {name: [] for name in runs}
    with tempfile.TemporaryDirectory() as cwd:
        for command in runs.values():
            once(command, cwd)  # bytecode written, files in the page cache
        for _ in range(repeat):
            for name, command in runs.items():
                results[name].append(once(command, cwd))
    return results


def table(results: dict[str, list[tuple[float, float, float]]], load: float, interpreter: str) -> str:
    """The page's table: median CPU, its ratio to the baseline, the goal, peak memory."""
    base = statistics.median(cpu for cpu, _, _ in results["python -c pass"])
    rows = ["| command | CPU (median) | ratio to `python -c pass` | goal | peak memory |",
            "|---|---:|---:|---:|---:|",
            f"| `python -c pass` (the baseline: {interpreter}) | {base * 1000:.0f} ms | 1× | | "
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
    at = measured_at(load)
    if not interpreter.startswith("a virtualenv"):  # another interpreter's aeroexec: not necessarily this checkout's
        at = at.replace("commit ", "the checkout at commit ", 1) + " (the aeroexec measured is the interpreter's own)"
    rows.append(f"\nMeasured by `python bench/startup.py --docs` (CPU time, user + system; {repeat} interleaved runs "
                f"of each, Python {sys.version_info.major}.{sys.version_info.minor}) at {at}.")
    return "\n".join(rows)


def default_venv() -> Path:
    """The bench's virtualenv of this checkout: one per checkout (its folder's hash in the name), so two checkouts
    measured at once (worktrees) never install themselves over each other's virtualenv mid-measurement."""
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    checkout = hashlib.sha256(str(ROOT).encode()).hexdigest()[:8]
    return Path(tempfile.gettempdir()) / f"aeroexec-bench-{getpass.getuser()}" / f"startup-venv-py{version}-{checkout}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs of each command (default 7)")
    parser.add_argument("--python", type=Path, help="measure this interpreter's installed aeroexec instead")
    parser.add_argument("--venv", type=Path, default=default_venv(), help="where the bench's virtualenv is kept")
    parser.add_argument("--docs", action="store_true", help=f"rewrite the start-up table of {PAGE.relative_to(ROOT)}")
    args = parser.parse_args()
    if args.python is not None:
        python, interpreter = args.python, f"`{args.python}`"
    else:
        python, interpreter = installed_venv(args.venv), "a virtualenv with `pip install .` of this checkout"
    load = load_average()
    results = measure(python, args.repeat)
    text = table(results, load, interpreter)
    print(text)
    for name, runs in results.items():
        cpus = sorted(c for c, _, _ in runs)
        walls = sorted(w for _, w, _ in runs)
        print(f"  {name}: CPU {cpus[0] * 1000:.0f}-{cpus[-1] * 1000:.0f} ms, wall median "
              f"{statistics.median(walls) * 1000:.0f} ms", file=sys.stderr)
    if args.docs:
        write_section(PAGE, BEGIN, END, text)
        print(f"{PAGE}: start-up table rewritten", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
