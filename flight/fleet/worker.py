"""One worker process of a fleet spread over worker processes (:mod:`aeroexec.flight.fleet.workers`): its share of
the drones flown as a :class:`~aeroexec.flight.fleet.fleet_flight.FleetFlight`, in lockstep with the other workers
through the fleet's router.

The coordinator starts it as ``aeroexec fleet FLEET.yaml --worker`` and speaks with it in lines: one JSON
:class:`WorkerTask` on its stdin first, then ``go`` (fly), ``stop HOW`` (end every mission and land; a second
one leaves the drones as they are), ``left NAME`` (the worker whose first drone is NAME has gone: wait for it no
more); the end of its stdin is the coordinator gone (land). It answers on its stdout, one JSON object a line:
``{"ready": true}`` once its drones are set up and it has met the other workers, ``{"line": TEXT}`` for each event
line, and ``{"done": {drone: record}, "time": {...}}`` at the end. Its warnings go to its stderr, as a run's do.
"""

from __future__ import annotations

import _thread
import dataclasses
import json
import logging
import signal
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from aeroexec.flight.fleet.fleet_flight import FleetFlight
from aeroexec.flight.fleet.status import drone_status, event_line, summary_line
from aeroexec.flight.spec import FlightError, FlightSpec

logger = logging.getLogger(__name__)

MEETING = 120.0  # wall seconds a worker may take to meet the others through the router


@dataclass
class WorkerTask:
    """What one worker flies: ``drones`` (its share, by name), ``peers`` (every other worker's first drone -> its
    drones), through the router at ``endpoint`` with the credentials in ``credentials``."""

    endpoint: str
    token: str
    output: str
    credentials: str
    drones: list[str]
    peers: dict[str, list[str]]
    base: dict[str, Any]  # the flight every drone shares (:func:`spec_record`)
    speed: float | None = None
    telemetry_rate: float = 5.0
    quiet: bool = False
    everyone: list[str] = field(default_factory=list)  # every drone flown by the fleet's workers


def spec_record(spec: FlightSpec) -> dict[str, Any]:
    """``spec`` as JSON can hold it (:func:`spec_from_record` reads it back)."""
    return json.loads(json.dumps(dataclasses.asdict(spec), default=str))


def spec_from_record(record: dict[str, Any]) -> FlightSpec:
    fields = {f.name: f for f in dataclasses.fields(FlightSpec)}
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in record.items() if k in fields}
    values["mission"] = Path(values["mission"])
    return FlightSpec(**values)


class Worker:
    """The worker's side of the lines above; ``fleet_spec`` is the fleet file as loaded, ``out`` the coordinator's
    pipe."""

    def __init__(self, fleet_spec: Any, task: WorkerTask, out: IO[str]) -> None:
        self.spec, self.task, self.out = fleet_spec, task, out
        self._lock = threading.Lock()
        self._go = threading.Event()
        self._stopped: str | None = None  # asked to stop before flying
        self.fleet: FleetFlight | None = None
        self.node: Any = None

    def tell(self, **message: Any) -> None:
        with self._lock:
            self.out.write(json.dumps(message) + "\n")
            self.out.flush()

    def listen(self, lines: IO[str]) -> None:
        """Read the coordinator's lines (a thread of their own) until its pipe closes."""
        for line in lines:
            word, _, rest = line.strip().partition(" ")
            if word == "go":
                self._go.set()
            elif word == "stop":
                self._stop(rest or "Ctrl-C")
            elif word == "left" and self.node is not None and self.node.in_lockstep is not None:
                self.node.in_lockstep.leave(rest)
        if self.node is not None and self.node.in_lockstep is not None:  # the coordinator (and its router) gone
            for peer in list(self.node.in_lockstep.peers):
                self.node.in_lockstep.leave(peer)
        if not self._go.is_set():
            self._stopped = "the fleet's coordinator ended"
            self._go.set()
        elif self.fleet is not None:
            self.fleet.stop("the fleet's coordinator ended")

    def _stop(self, how: str) -> None:
        """The operator's signal to the coordinator, as if it had come here (a second one leaves the drones as
        they are)."""
        if not self._go.is_set():
            self._stopped = how
            self._go.set()
            return
        number = signal.SIGINT if how == "Ctrl-C" else getattr(signal, how, signal.SIGTERM)
        _thread.interrupt_main(number)

    def fly(self) -> int:
        """Set the share up, meet the others, fly when told; the process's exit status."""
        from aeroexec.fleet import members

        task = self.task
        base = spec_from_record(task.base)
        mine = set(task.drones)
        drones = [d for d in self.spec.flown if d.name in mine]
        output = Path(task.output)
        membership = members.work(self.spec, Path(task.credentials), [task.endpoint], tuple(task.drones))
        try:
            self.node = node = membership.node(task.token)
            node.lockstep(task.drones[0], task.peers)
            self.fleet = fleet = FleetFlight(node, drones, base, output=output, speed=task.speed,
                                             telemetry_rate=task.telemetry_rate, everyone=tuple(task.everyone),
                                             notify=logger.info,  # the coordinator tells the operator
                                             report=lambda problem: print(problem, file=sys.stderr, flush=True))
            try:
                fleet.open()
                if not task.quiet:
                    for member in fleet.members:
                        member.engine.log.subscribe(self._shower(member.name))
                if not node.meet(MEETING, self._go):
                    if self._stopped is not None:
                        return 130
                    raise FlightError(f"the fleet's other workers were not heard through its router at "
                                      f"{task.endpoint} within {MEETING:.0f} s")
                self.tell(ready=True)
                self._go.wait()
                if self._stopped is not None:
                    return 130
                outcomes = fleet.fly()
                done = {m.name: {**drone_status(outcomes[m.name]), "summary": summary_line(m, outcomes[m.name])}
                        for m in fleet.members}
                self.tell(done=done, time=fleet.time)
                return 0
            finally:
                fleet.close()
        finally:
            if self.node is not None:
                self.node.close()
            membership.close()

    def _shower(self, name: str) -> Any:
        def show(event: Any) -> None:
            if (line := event_line(name, event)) is not None:
                self.tell(line=line)

        return show


def serve(fleet_spec: Any, stdin: IO[str] = sys.stdin, stdout: IO[str] = sys.stdout) -> int:
    """Be a worker: read the task, fly it (the entry of ``aeroexec fleet FLEET.yaml --worker``)."""
    first = stdin.readline()
    try:
        task = WorkerTask(**json.loads(first))
    except (ValueError, TypeError) as error:
        print(f"aeroexec fleet --worker: not a worker's task on stdin ({error}); only aeroexec fleet starts workers",
              file=sys.stderr)
        return 2
    from aeroexec.fleet.credentials import CredentialsError
    from aeroexec.fleet.transport import TransportError

    worker = Worker(fleet_spec, task, stdout)
    threading.Thread(target=worker.listen, args=(stdin,), name="aeroexec-worker-lines", daemon=True).start()
    try:
        return worker.fly()
    except FlightError as error:  # its drones cannot fly: said on its stderr, the coordinator says which worker
        print(error, file=sys.stderr, flush=True)
        return 2 if error.usage else 1
    except (TransportError, CredentialsError) as error:
        print(error, file=sys.stderr, flush=True)
        return 1
    except KeyboardInterrupt:  # stopped before its drones flew
        return 130


__all__ = ["Worker", "WorkerTask", "serve", "spec_from_record", "spec_record"]
