"""A case flown by real ``aeroexec run`` processes: what the operator sees (the exit status, the last line) against
what the run's files say. Faults are those of a process: SIGTERM, SIGHUP, or ``kill -9`` then ``aeroexec run
--resume``, and a full disk (the event log's writer given a disk that fills after a number of bytes).

A signal is sent at the fault's engine time by the process to itself (:data:`SIGNAL_AT`: a tick callback of its
engine, at the first period at or after that time), never by this process watching the run's files: a run without
a terminal flies as fast as it can, so a signal sent from outside lands wherever the run has got to when the sender
is scheduled (seconds of engine time later on a loaded machine, or after the run ended), and the case's seed would
not decide its outcome. The signal is a real one all the same: the kernel delivers it, the run's handlers take it
as they take ``kill``'s."""

from __future__ import annotations

import contextlib
import json
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from aeroexec.rehearsal.simulation.cases import Case
from aeroexec.rehearsal.simulation.flights import Flown, Part

#: the faults that are a signal to the process, and their signal
SIGNALS = {"crash": signal.SIGKILL, "sigterm": signal.SIGTERM, "sighup": signal.SIGHUP}
LIMIT = 300.0  # wall seconds a process may take before it is called hung (a violation, never a wait that fails)
# python -c FULL_DISK ROOM ARGS...: the event log's writer on a disk that fills after ROOM bytes
FULL_DISK_PART = """
import errno, os, sys
from aeroexec.flight import flight_log


class FullDisk:
    room = int(sys.argv.pop(1))

    def __getattr__(self, name):
        return getattr(os, name)

    def write(self, fd, data):
        if self.room <= 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        part = bytes(data[:self.room])
        self.room -= len(part)
        return os.write(fd, part)


flight_log.os = FullDisk()
"""
# python -c SIGNAL_AT NAME TIME ARGS...: the signal NAME (SIGTERM, SIGHUP, SIGKILL) sent by the process to itself at
# the first engine period at or after TIME s of engine time (none if the run ends before)
SIGNAL_AT = """
import os, signal, sys
from aeroexec.flight.session import FlightSession

SIGNAL, AT = signal.Signals[sys.argv.pop(1)], float(sys.argv.pop(1))
opened = FlightSession.open


def open_then_signal(session, *args, **kwargs):
    result = opened(session, *args, **kwargs)
    engine, sent = session.engine, []

    def at_time():
        if not sent and engine.now() >= AT:
            sent.append(SIGNAL)
            os.kill(os.getpid(), SIGNAL)

    engine.tick_callbacks.append(at_time)
    return result


FlightSession.open = open_then_signal
"""
MAIN = """
from aeroexec.cli.main import main
sys.exit(main(sys.argv[1:]))
"""
FULL_DISK = FULL_DISK_PART + MAIN


def last_state(part: Part, states: list[dict]) -> None:
    """``part``'s drone as its last ``state`` record leaves it (armed, where, landed or not)."""
    if states:
        part.armed, part.position = bool(states[-1].get("armed")), tuple(states[-1].get("position", (0, 0, 0)))
        part.altitude = part.position[2]
        part.landed_state = str(states[-1].get("landed_state", ""))


def _records(folder: Path) -> list[dict[str, Any]]:
    path = folder / "events.jsonl"
    found = []
    if path.is_file():
        for line in path.read_bytes().splitlines():
            with contextlib.suppress(ValueError):
                found.append(json.loads(line))
    return found


def _part(folder: Path, process: Any, err: str, killed: bool, parts_before: int = 0
          ) -> tuple[Part, int | None, str]:
    from aeroexec.flight.run_status import EXIT_STATUS, FlightOutcome, RunStatus, last_part

    part = Part(crashed=killed)
    lines = [line for line in err.splitlines() if line.strip()]
    last = lines[-1] if lines else ""
    if "please report it" in err or process.returncode == 70:
        part.error = f"exit status {process.returncode}: {last}"
    records = last_part(_records(folder))
    ended = [r for r in records if r.get("kind") == "run_ended"]
    states = [r for r in records if r.get("kind") == "state"]
    last_state(part, states)
    if killed:
        return part, None, last
    parts = sum(r.get("kind") in ("log_started", "log_resumed") for r in _records(folder))
    if parts <= parts_before and process.returncode in (1, 2):  # refused: nothing of it in the log
        part.refused = last
        return part, process.returncode, last
    incomplete = next((line.split("(", 1)[1].split(")", 1)[0] for line in lines
                       if line.startswith("the event log is incomplete")), None)
    faults = [line.removeprefix("failed: ") for line in lines if line.startswith("failed: ")]
    part.state_known = incomplete is None and bool(states)
    said = next((line.split(": ", 1)[1].split(" at t=", 1)[0] for line in lines
                 if line.startswith(f"{case_name(folder)}: ") and " at t=" in line), None)
    if ended:
        status = RunStatus(ended[-1]["detail"], list((ended[-1].get("data") or {}).get("reasons", [])))
        part.outcome = FlightOutcome(status, faults, incomplete, folder)
    elif said in EXIT_STATUS:  # the log stopped short (a full disk): the run's summary says how it ended
        part.outcome = FlightOutcome(RunStatus(said), faults, incomplete, folder)
    else:
        part.error = f"exit status {process.returncode} without saying how the run ended: {last}"
    link = [r for r in records if r.get("kind", "").startswith("drone_ground_link")]
    part.link_ok = not link or link[-1]["kind"] != "drone_ground_link_lost"
    return part, process.returncode, last


def case_name(folder: Path) -> str:
    """The mission's name in the run's lines (its file name, beside the run's folder)."""
    return next((p.name for p in folder.parent.glob("mission.*")), "mission")


def fly_process(case: Case, scratch: Path) -> Flown:
    """Fly ``case`` by ``aeroexec run`` processes, its files in ``scratch``."""
    mission = scratch / f"mission{case.mission.suffix}"
    mission.write_text(case.mission.text)
    options = ["--seed", str(case.seed), "--max-time", f"{60.0 + 10.0 * case.mission.leaves:g}", "--link-grace", "10"]
    for name, text, flag in (("rules.txt", case.rules, "--rules"), ("safety.yaml", case.safety_rules,
                                                                     "--safety-rules")):
        if text:
            (scratch / name).write_text(text)
            options += [flag, str(scratch / name)]
    folder = scratch / "run"
    flown = Flown(case, folder)
    flown.allowed_points.update(tuple(round(v, 1) for v in p) for p in case.mission.points)
    disk = case.fault("disk_full")
    killer = next((f for f in case.faults if f.kind in SIGNALS), None)
    command = ["run", str(mission), "--quiet", "--output", str(folder), *options]
    head = [sys.executable, "-c", FULL_DISK, str(disk.size)] if disk else [sys.executable, "-m", "aeroexec.cli.main"]
    first = head
    sent: int | None = None  # the signal the process sends itself at the fault's time, if it is still running then
    if killer is not None:
        sent = SIGNALS[killer.kind]
        first = [sys.executable, "-c", (FULL_DISK_PART if disk else "") + SIGNAL_AT + MAIN,
                 *([str(disk.size)] if disk else []), sent.name, f"{killer.time!r}"]
    began = time.perf_counter()
    process = subprocess.Popen([*first, *command], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               cwd=scratch)
    try:
        _, err = process.communicate(timeout=LIMIT)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        flown.parts.append(Part(error=f"the process did not end within {LIMIT:g} s"))
        return flown
    killed = sent == signal.SIGKILL and process.returncode == -signal.SIGKILL
    closed = any(r.get("kind") == "log_closed" for r in _records(folder))
    # the process died of the signal itself with its run recorded whole: the signal came after the run had ended
    # (its handlers gone, the process exiting), and the exit is the signal's, not the run's
    after_end = closed and (killed or (sent is not None and process.returncode == -sent))
    if after_end:
        killed = False  # the run had ended (its log closed) when kill -9 reached the process: nothing to resume
    part, status, last = _part(folder, process, err, killed)
    flown.parts.append(part)
    # a process killed after its run ended exits as the kill says (-9), not as its run did: nothing to compare
    flown.exit_status, flown.last_line = (None, "") if after_end else (status, last)
    if killed:
        before = sum(r.get("kind") in ("log_started", "log_resumed") for r in _records(folder))
        again = subprocess.run([*head, "run", "--resume", str(folder), "--quiet"], capture_output=True, text=True,
                               cwd=scratch, timeout=LIMIT)
        part, status, last = _part(folder, again, again.stderr, False, before)
        flown.parts.append(part)
        flown.exit_status, flown.last_line = status, last
    flown.wall = time.perf_counter() - began
    return flown


__all__ = ["fly_process"]
