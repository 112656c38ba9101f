"""A fleet spread over worker processes: the coordinator's side of ``aeroexec fleet --workers N``.

The coordinator holds the fleet's router; each worker (:mod:`aeroexec.flight.fleet.worker`, one process each,
started as ``aeroexec fleet FLEET.yaml --worker``) flies a share of the drones and links to the others through the
router, in lockstep: one simulated time the workers agree on, so the event logs are the same per seed whatever the
number of workers (and at real time when paced). The workers are set up side by side, meet through the router,
then fly when every one is ready. The coordinator relays their event lines, passes the operator's signals on
(a second one leaves the drones as they are, as in one process), tells the others when a worker ends before its
drones did (its drones end ``failed``, with the reason), and writes the fleet's status.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import os
import queue
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.flight.fleet.status import write_status
from aeroexec.flight.fleet.worker import WorkerTask, spec_record
from aeroexec.flight.spec import FlightError, FlightSpec

logger = logging.getLogger(__name__)

DRONES_PER_WORKER = 100  # a fleet of fewer drones than this per core flies in one process by default
SET_UP = 900.0  # wall seconds the workers may take to set their drones up and meet
ENDING = 60.0  # wall seconds a worker is given to end once its pipe closed, before it is killed


def default_workers(drones: int) -> int:
    """Workers for a fleet of ``drones``: one per core, for fleets large enough to need more than one."""
    return max(1, min(os.cpu_count() or 1, -(-drones // DRONES_PER_WORKER)))


def shares(names: list[str], workers: int) -> list[list[str]]:
    """``names`` split in ``workers`` runs of consecutive drones, as even as can be."""
    size, extra = divmod(len(names), workers)
    out, start = [], 0
    for k in range(workers):
        end = start + size + (1 if k < extra else 0)
        out.append(names[start:end])
        start = end
    return [share for share in out if share]


@dataclass
class _Process:
    drones: list[str]
    popen: subprocess.Popen
    ready: bool = False
    done: dict[str, Any] | None = None
    time: dict[str, float] = field(default_factory=dict)
    ended: bool = False

    @property
    def name(self) -> str:
        return self.drones[0]


class WorkerFleet:
    """The drones of ``fleet_spec`` (a loaded fleet file) flown by ``workers`` processes through the router at
    ``endpoint`` (its credentials in ``credentials``). ``base`` is the flight every drone shares; ``lines``
    receives each event line; ``notify`` what the operator should read."""

    def __init__(self, fleet_spec: Any, base: FlightSpec, *, workers: int, endpoint: str, token: str,
                 credentials: Path, output: Path, speed: float | None = None, quiet: bool = False,
                 verbose: bool = False, lines: Callable[[str], None] = print,
                 notify: Callable[[str], None] = logger.warning) -> None:
        self.spec, self.base, self.output = fleet_spec, base, Path(output)
        self.endpoint, self.token, self.credentials = endpoint, token, Path(credentials)
        self.speed, self.quiet, self.verbose = speed, quiet, verbose
        self.lines, self.notify = lines, notify
        names = [d.name for d in fleet_spec.flown]
        self.shares = shares(names, workers)
        self.processes: list[_Process] = []
        self._messages: queue.Queue[tuple[_Process, dict[str, Any] | None]] = queue.Queue()
        self._stops = 0
        self.time: dict[str, float] = {}

    # -- set-up ------------------------------------------------------------------------------------------------------
    def open(self) -> WorkerFleet:
        """Start every worker and wait until each has set its drones up and met the others; FlightError (every
        worker ended) when one cannot."""
        everyone = [name for share in self.shares for name in share]
        command = [sys.executable, "-m", "aeroexec", *(["-v"] if self.verbose else []), "fleet",
                   str(self.spec.file), "--worker"]
        for share in self.shares:
            task = WorkerTask(endpoint=self.endpoint, token=self.token, output=str(self.output),
                              credentials=str(self.credentials), drones=share,
                              peers={s[0]: s for s in self.shares if s is not share}, base=spec_record(self.base),
                              speed=self.speed, telemetry_rate=self.spec.telemetry_rate, quiet=self.quiet,
                              everyone=everyone)
            popen = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     start_new_session=True)  # the operator's signals come through the coordinator
            process = _Process(share, popen)
            self.processes.append(process)
            self._send(process, json.dumps(dataclasses.asdict(task)))
            threading.Thread(target=self._read, args=(process,), name=f"aeroexec-worker-{process.name}",
                             daemon=True).start()
        deadline = time.monotonic() + SET_UP
        try:
            while not all(p.ready for p in self.processes):
                process, message = self._next(deadline)
                if process is None:
                    raise FlightError(f"the fleet's workers were not ready within {SET_UP:.0f} s")
                if message is None:
                    raise FlightError(f"the worker flying {_named(process.drones)} ended before its drones took off "
                                      f"(exit status {process.popen.wait()}): see its lines above")
        except BaseException:
            self.close()
            raise
        return self

    # -- the flight ----------------------------------------------------------------------------------------------------
    def fly(self) -> dict[str, dict[str, Any]]:
        """Fly every share; each drone's record (:func:`~aeroexec.flight.fleet.status.drone_status` and its summary
        line). The operator's Ctrl-C (KeyboardInterrupt, or SIGTERM/SIGHUP through :mod:`aeroexec.flight.signals`)
        is passed on to every worker."""
        cpu = time.process_time()  # the coordinator's: its router relays the workers' messages
        for process in self.processes:
            self._send(process, "go")
        while not all(p.ended for p in self.processes):
            try:
                process, message = self._next(None)
            except KeyboardInterrupt as interrupt:
                self.stop(getattr(interrupt, "signal_name", "Ctrl-C"))
                continue
            if message is None:
                self._ended(process)
        records = {}
        for process in self.processes:
            records.update(process.done or {})
        self.time = {"simulated": max((p.time.get("simulated", 0.0) for p in self.processes), default=0.0),
                     "wall": max((p.time.get("wall", 0.0) for p in self.processes), default=0.0),
                     "cpu": sum(p.time.get("cpu", 0.0) for p in self.processes) + time.process_time() - cpu,
                     "workers": len(self.processes)}
        order = [d.name for d in self.spec.flown]
        records = {name: records[name] for name in order if name in records}
        write_status(self.output, self.spec.name, {n: {k: v for k, v in r.items() if k != "summary"}
                                                   for n, r in records.items()}, {"time": self.time})
        return records

    def stop(self, how: str = "Ctrl-C") -> None:
        """Pass the operator's interrupt on to every worker (a second one leaves the drones as they are)."""
        self._stops += 1
        if self._stops == 1:
            self.notify(f"interrupted by the operator ({how}): every drone aborts and lands ({how} again leaves "
                        f"them as they are)")
        elif self._stops == 2:
            self.notify("interrupted again: leaving the drones as they are")
        self._tell_all(f"stop {how}")

    def _tell_all(self, line: str) -> None:
        for process in self.processes:
            if not process.ended:
                self._send(process, line)

    def _ended(self, process: _Process) -> None:
        status = process.popen.wait()
        process.ended = True
        if process.done is None:  # it died with its drones: they did not end as asked
            reason = f"its worker process ended unexpectedly (exit status {status}): see its lines above"
            process.done = {name: {"status": "failed", "reasons": [reason], "faults": [reason], "exit_status": 1,
                                   "log_incomplete": True, "summary": f"{name}: failed ({reason})"}
                            for name in process.drones}
            self.notify(f"the worker flying {_named(process.drones)} ended unexpectedly (exit status {status}): its "
                        f"drones are reported failed; the others fly on")
            self._tell_all(f"left {process.name}")

    # -- the workers' lines --------------------------------------------------------------------------------------------
    def _read(self, process: _Process) -> None:
        for line in process.popen.stdout:
            try:
                message = json.loads(line)
            except ValueError:
                self.lines(line.rstrip("\n"))  # not the protocol's: a line of the worker's own (a mission's print)
                continue
            if isinstance(message, dict):
                self._messages.put((process, message))
        self._messages.put((process, None))

    def _next(self, deadline: float | None) -> tuple[Any, dict[str, Any] | None]:
        """The next message of a worker handled (lines shown, ready and done noted); None, None at the deadline."""
        while True:
            wait = None if deadline is None else max(0.0, deadline - time.monotonic())
            try:
                process, message = self._messages.get(timeout=0.5 if wait is None else min(wait, 0.5))
            except queue.Empty:
                if deadline is not None and time.monotonic() >= deadline:
                    return None, None
                continue
            if message is None:
                return process, None
            if "line" in message:
                self.lines(str(message["line"]))
                continue
            if message.get("ready"):
                process.ready = True
            if "done" in message:
                process.done, process.time = message["done"], message.get("time", {})
            return process, message

    def _send(self, process: _Process, line: str) -> None:
        try:
            process.popen.stdin.write(line + "\n")
            process.popen.stdin.flush()
        except (BrokenPipeError, OSError, ValueError):  # it has ended: its end is read from its stdout
            pass

    def close(self) -> None:
        """End every worker (idempotent, never hangs): its pipe closed lands its drones; one that does not end
        within :data:`ENDING` s is killed."""
        for process in self.processes:
            with contextlib.suppress(OSError):
                process.popen.stdin.close()
        deadline = time.monotonic() + ENDING
        for process in self.processes:
            try:
                process.popen.wait(max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                logger.error("the worker flying %s did not end within %.0f s: killed", _named(process.drones),
                             ENDING)
                process.popen.kill()
                process.popen.wait()


def _named(drones: list[str]) -> str:
    return ", ".join(drones) if len(drones) <= 3 else f"{drones[0]} … {drones[-1]} ({len(drones)} drones)"


__all__ = ["DRONES_PER_WORKER", "WorkerFleet", "default_workers", "shares"]
