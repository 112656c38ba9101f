#!/usr/bin/env python3
"""The held-back Aerostack2 missions (tests/aerostack/data/heldback/SOURCES.md) flown as their authors would fly
them: ``aeroexec run FILE`` alone (no fleet file, no world, no flags; ``python -m aeroexec`` of this Python),
each in its own process with a time limit, from its project's folder (a copy of it) as the projects' launch
sessions run their missions, and a table of how each ended, read from the run's event logs (one per drone):

- ``flew``: flew to completion — every drone took off, every behavior the mission requested reached its goal, none
  of its requests was refused, the drone landed before the mission ended and was disarmed, and the run ended
  completed (status 0);
- ``flew, then exited N``: all of that, and then the script ended itself with ``sys.exit(N)``, N not 0, as it
  would under ``python3`` (the status is its author's);
- ``flew, left in the air``: status 0 and all of the first, but the script ended with the drone flying (it never
  lands it: under ``python3`` it would be left hovering; aeroexec's run lands it). Counted apart too;
- ``incomplete``: the run ended with status 0 but its logs show no flight to completion (the reason: a drone that
  never took off, a behavior that ended short of its goal, a request refused, a drone not landed or not disarmed);
- ``refused`` (before flight, with the reason the run gave), ``failed`` (the reason), ``timeout``.

    python tools/aerostack2_survey.py [--jobs 2] [--limit 300] [FILE...]

The last line gives the figure, how many of the set flew to completion, and beside it, apart, how many flew to
completion and then exited with a non-zero status of the script's own, and how many flew what they asked and left
the drone in the air.
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
    verdict: str  # "flew", "flew, then exited N", "flew, left in the air", "incomplete", "refused", "failed",
    # "timeout"
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


def fly(path: Path, limit: float, project: Path | None = None) -> Outcome:
    """``aeroexec run`` of the mission at ``path`` from its project's folder (``project``; by default the held-back
    set's ``OWNER__NAME`` folder holding it), as the projects' launch sessions run their missions (tmuxinator's
    ``root: ./``): a copy of the folder, so the run's output folder is made in the copy, not among the collected
    files. The verdict is read from the run's event logs (:func:`flight_of`), not from its exit status alone."""
    if project is None:
        project = HELDBACK / path.relative_to(HELDBACK).parts[0]
    name = str(path.relative_to(project.parent))
    with tempfile.TemporaryDirectory(prefix="as2survey") as folder:
        root = Path(folder) / project.name
        shutil.copytree(project, root)
        try:
            done = subprocess.run([sys.executable, "-m", "aeroexec", "run", str(path.relative_to(project))],
                                  cwd=root, capture_output=True, text=True, timeout=limit,
                                  stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            return Outcome(name, "timeout", None, f"still running after {limit:.0f} s")
        logs = sorted(Path(folder).rglob("events.jsonl"))  # one per drone (a script's fleet: OUTPUT/<drone>/)
        reason = _reason(done.stderr.replace(f"{folder}/", ""), logs[0].parent if logs else Path(folder))
        if done.returncode == 3 or (done.returncode == 1 and not logs):
            return Outcome(name, "refused", done.returncode, reason)
        flight = flight_of(logs)
        if flight.completed and done.returncode == 0 and flight.exit_status is None:
            return Outcome(name, "flew", 0, "")
        if flight.completed and flight.exit_status is not None and done.returncode != 0:  # the run: failed (1)
            return Outcome(name, f"flew, then exited {flight.exit_status}", done.returncode,
                           f"landed and disarmed, then the script's own exit: sys.exit({flight.exit_status})")
        if done.returncode == 0 and flight.left_in_air:  # what it asked flew; it never landed the drone itself
            return Outcome(name, "flew, left in the air", 0, flight.short_of)
        if done.returncode == 0:  # ended as its author meant, yet not a flight to completion (an LED test...)
            return Outcome(name, "incomplete", 0, flight.short_of)
        return Outcome(name, "failed", done.returncode, reason)


@dataclass
class Flight:
    """What a run's event logs say of its flight: whether it flew to completion, and whether the script exited with
    a status of its own (``sys.exit(N)``, N not 0) after it."""

    completed: bool
    short_of: str  # why it did not fly to completion ("" when it did)
    exit_status: int | None  # the script's own exit status, when its exit ended the run (not 0)
    left_in_air: bool = False  # all else held, but the mission ended with a drone in the air (the run landed it)


#: Why a flight whose every other check held is not one to completion: the script left the drone flying.
IN_AIR = "the mission ended with the drone in the air (the run landed it)"
#: A behavior's ends short of its goal.
_SHORT = ("TIME_OUT", "WRONG_PROGRESS", "FAILED", "INTERRUPTED")
_SCRIPT_EXIT = re.compile(r"ScriptExit: the script exited with status (-?\d+)$")


def flight_of(logs: list[Path]) -> Flight:
    """Flown to completion, from the event log of each drone of the run: the drone took off; every behavior the
    mission requested reached its goal (none ended ``TIME_OUT``, ``WRONG_PROGRESS``, ``FAILED`` or
    ``INTERRUPTED``) and none of its requests was refused (``rejected``, ``failed_preconditions``); the drone landed
    after its last take-off and was disarmed after that landing; the run ended ``completed``, or ``failed`` by the
    script's own exit with a non-zero status (``ScriptExit``) and nothing else (``exit_status``). The landing is the
    mission's: before the mission ended, not the run's landing of a drone the mission left in the air."""
    if not logs:
        return Flight(False, "no event log", None)
    statuses: set[int | None] = set()
    in_air = []
    for log in logs:
        short_of, status = _drone_flight(log)
        drone = f"{log.parent.name}: " if len(logs) > 1 else ""
        if short_of == IN_AIR:
            in_air.append(f"{drone}{short_of}")
        elif short_of:
            return Flight(False, f"{drone}{short_of}", None)
        statuses.add(status)
    if in_air:
        return Flight(False, in_air[0], None, left_in_air=True)
    if len(statuses) != 1:
        return Flight(False, "the drones' runs ended differently", None)
    return Flight(True, "", statuses.pop())


def _drone_flight(log: Path) -> tuple[str, int | None]:
    """Why one drone's run did not fly to completion ("" when it did), and the script's own exit status, if any."""
    records = [json.loads(line) for line in log.read_text().splitlines() if line.strip()]
    took_off = landed = disarmed = ended_at = -1
    achieved = 0
    ended: dict | None = None
    for i, record in enumerate(records):
        kind = record.get("kind")
        mission = (record.get("data") or {}).get("source") == "mission"
        if kind in ("rejected", "failed_preconditions") and mission:
            return f"a request was refused: {record.get('behavior')}: {record.get('detail')}"[:160], None
        if kind in _SHORT and mission:
            return f"{record.get('behavior')} ended {kind}: {record.get('detail')}"[:160], None
        if kind == "GOAL_ACHIEVED" and mission:
            achieved += 1
        elif kind == "drone_takeoff_complete":
            took_off = i
        elif kind == "drone_landed":
            landed = i
        elif kind == "drone_disarmed":
            disarmed = i
        elif kind in ("mission_completed", "mission_failed") and ended_at < 0:
            ended_at = i
        elif kind == "run_ended":
            ended = record
    if took_off < 0 or not achieved:
        return "the drone never took off", None
    if landed < took_off:
        return "the drone did not land after its last take-off", None
    if 0 <= ended_at < landed:
        return IN_AIR, None
    if disarmed < landed:
        return "the drone was not disarmed after landing", None
    if ended is None:
        return "the run did not end (no run_ended record)", None
    if ended.get("detail") == "completed":
        return "", None
    reasons = (ended.get("data") or {}).get("reasons") or []
    exits = [_SCRIPT_EXIT.search(str(r)) for r in reasons]
    if len(exits) == 1 and exits[0] is not None and int(exits[0].group(1)) != 0:
        return "", int(exits[0].group(1))
    return f"the run ended {ended.get('detail')}: {'; '.join(map(str, reasons))}"[:160], None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--limit", type=float, default=300.0, help="seconds of wall time per run")
    arguments = parser.parse_args(argv)
    files = [p.resolve() for p in arguments.files] or missions()
    with ThreadPoolExecutor(arguments.jobs) as pool:
        outcomes = list(pool.map(lambda p: fly(p, arguments.limit), files))
    report(outcomes)
    return 0


def report(outcomes: list[Outcome]) -> None:
    """The table, one line a mission, and the figures: flown to completion, and beside it (not in it) flown to
    completion and then exited non-zero by the script's own exit."""
    width = max(len(o.file) for o in outcomes)
    verdicts = max(len(o.verdict) for o in outcomes)
    for outcome in outcomes:
        status = "-" if outcome.status is None else str(outcome.status)
        print(f"{outcome.file:<{width}}  {outcome.verdict:<{verdicts}} {status:>2}  {outcome.reason}")
    flew = sum(o.verdict == "flew" for o in outcomes)
    exited = sum(o.verdict.startswith("flew, then exited") for o in outcomes)
    in_air = sum(o.verdict == "flew, left in the air" for o in outcomes)
    print(f"flew to completion: {flew} of {len(outcomes)}; "
          f"flew to completion, then exited non-zero by the script's own exit: {exited} of {len(outcomes)}; "
          f"flew what it asked, then left the drone in the air (the run landed it): {in_air} of {len(outcomes)}")


if __name__ == "__main__":
    sys.exit(main())
