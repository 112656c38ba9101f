#!/usr/bin/env python3
"""The held-back Aerostack2 missions (tests/aerostack/data/heldback/SOURCES.md) flown as their authors would fly
them: ``aeroexec run FILE`` alone (no fleet file, no world, no flags; ``python -m aeroexec`` of this Python),
each in its own process with a time limit, from its project's folder (a copy of it) as the projects' launch
sessions run their missions, and a table of how each ended: flew to completion, refused (with the
reason the run gave), exited (flew and landed, then the script exited with a non-zero status of its own), or
failed.

    python tools/aerostack2_survey.py [--jobs 2] [--limit 300] [FILE...]

The last line is the figure: how many of the set flew to completion.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from aeroexec.dialects.aerostack2.plans import is_aerostack2_plan

REPOSITORY = Path(__file__).resolve().parent.parent
HELDBACK = REPOSITORY / "tests" / "aerostack" / "data" / "heldback"
#: The missions of the set: the scripts, trees and interpreter plans SOURCES.md names, less the modules a script
#: imports (no mission of their own) and the JSON files that are not interpreter plans (world configs).
MISSION = re.compile(r"^\| `([^`]+\.(?:py|xml|json))` \|", re.MULTILINE)
SUPPORT = ("/__init__.py", "follow_drone_module.py", "generateMap.py")


@dataclass
class Outcome:
    """How one mission's run ended."""

    file: str
    verdict: str  # "flew", "refused", "exited" (landed, then a non-zero exit of the script's own), "failed", "timeout"
    status: int | None
    reason: str


def missions() -> list[Path]:
    names = MISSION.findall((HELDBACK / "SOURCES.md").read_text())
    return [HELDBACK / n for n in names
            if not n.endswith(SUPPORT) and (not n.endswith(".json") or is_aerostack2_plan((HELDBACK / n).read_text()))]


def _reason(err: str, out: Path) -> str:
    lines = [line.strip() for line in err.splitlines() if line.strip() and ": warning: " not in line]
    for i, line in enumerate(lines[:-1]):  # the summary's line under "completed with refused requests": the first
        if "completed with refused requests" in line:
            return lines[i + 1][:160]
        if ": failed at t=" in line:  # under "failed at": the last, the mission's own (a tree's: how it was halted)
            return lines[-1][:160]
    for marker in ("error:", "refused", "failed", "Error", "not "):
        for line in lines:
            if marker in line:
                return line[:160]
    log = out / "events.jsonl"
    if log.exists():
        for line in reversed(log.read_text().splitlines()):
            record = json.loads(line)
            if record.get("kind") in ("mission_failed", "rejected", "failed_preconditions"):
                return str(record.get("detail"))[:160]
    return (lines[-1] if lines else "")[:160]


def fly(path: Path, limit: float) -> Outcome:
    """``aeroexec run`` of the mission at ``path`` from its project's folder, as the projects' launch sessions run
    their missions (tmuxinator's ``root: ./``): a copy of the repository's collected files, so the run's output
    folder is made in the copy, not among the collected files."""
    name = str(path.relative_to(HELDBACK))
    project = name.split("/", 1)[0]
    with tempfile.TemporaryDirectory(prefix="as2survey") as folder:
        root = Path(folder) / project
        shutil.copytree(HELDBACK / project, root)
        try:
            done = subprocess.run([sys.executable, "-m", "aeroexec", "run", name.split("/", 1)[1]], cwd=root,
                                  capture_output=True, text=True, timeout=limit, stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            return Outcome(name, "timeout", None, f"still running after {limit:.0f} s")
        outputs = sorted(Path(folder).rglob("events.jsonl"))
        out = outputs[0].parent if outputs else Path(folder)
        if done.returncode == 0:
            return Outcome(name, "flew", 0, "")
        reason = _reason(done.stderr.replace(f"{folder}/", ""), out)  # the files as the held-back set names them
        refused = done.returncode == 3 or (done.returncode == 1 and not outputs)
        if not refused and _landed_then_exited(out):
            return Outcome(name, "exited", done.returncode, reason)
        return Outcome(name, "refused" if refused else "failed", done.returncode, reason)


#: Records of a flight that did not go as its script asked: a request refused, a behavior failed or timed out.
_TROUBLE = {"rejected", "failed_preconditions", "WRONG_PROGRESS", "TIME_OUT", "FAILED"}


def _landed_then_exited(out: Path) -> bool:
    """The run's flight ended landed with no request refused, and then the script exited with a status of its own
    (``sys.exit(1)``): not a completion (the run's status is the script's), told apart from a failure in flight."""
    log = out / "events.jsonl"
    if not log.exists():
        return False
    records = [json.loads(line) for line in log.read_text().splitlines()]
    kinds = [r.get("kind") for r in records]
    failed = [r for r in records if r.get("kind") == "mission_failed"]
    return ("drone_landed" in kinds and not _TROUBLE.intersection(kinds) and len(failed) == 1
            and "ScriptExit: the script exited with status" in str(failed[0].get("detail"))
            and kinds.index("drone_landed") < kinds.index("mission_failed"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--limit", type=float, default=300.0, help="seconds of wall time per run")
    arguments = parser.parse_args(argv)
    files = [p.resolve() for p in arguments.files] or missions()
    with ThreadPoolExecutor(arguments.jobs) as pool:
        outcomes = list(pool.map(lambda p: fly(p, arguments.limit), files))
    width = max(len(o.file) for o in outcomes)
    for outcome in outcomes:
        status = "-" if outcome.status is None else str(outcome.status)
        print(f"{outcome.file:<{width}}  {outcome.verdict:<8} {status:>2}  {outcome.reason}")
    flew = sum(o.verdict == "flew" for o in outcomes)
    print(f"flew to completion: {flew} of {len(outcomes)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
