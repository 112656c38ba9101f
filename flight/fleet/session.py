"""A fleet file flown from this process, from set-up to its end, as :class:`~aeroexec.flight.session.FlightSession`
is one drone's: the output folder, the fleet's token, its Zenoh membership (the fleet's router listening here, or
the drones' sessions through the fleet's router elsewhere), ``fleet.json`` for ``aeroexec ctl --fleet``, and the
drones, flown in this process (:class:`~aeroexec.flight.fleet.fleet_flight.FleetFlight`) or spread over worker
processes in lockstep (:class:`~aeroexec.flight.fleet.workers.WorkerFleet`). ``aeroexec fleet`` flies one; an
embedder too::

    with FleetSession(load_fleet("pair.yaml"), FlightSpec(mission=Path("pair.yaml"))) as fleet:
        drones = fleet.fly()             # each drone's record, and its summary line
    print(fleet_exit_status(drones))
"""

from __future__ import annotations

import logging
import secrets
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from aeroexec.engine.errors import Problem
from aeroexec.flight.fleet.fleet_flight import FleetFlight
from aeroexec.flight.fleet.status import drone_status, summary_line
from aeroexec.flight.output import prepare_output
from aeroexec.flight.run_status import FlightOutcome
from aeroexec.flight.spec import FlightSpec

logger = logging.getLogger(__name__)


class FleetSession:
    """The drones of ``fleet`` (a loaded fleet file, :func:`aeroexec.fleet.fleet_file.load_fleet`) flown from this
    process: :meth:`open` sets the fleet up (raising :class:`~aeroexec.flight.spec.FlightError` for what the
    operator must fix, :class:`~aeroexec.fleet.transport.TransportError` or
    :class:`~aeroexec.fleet.credentials.CredentialsError` for the link, before anything flies), :meth:`fly` flies
    every drone until each flight has ended, :meth:`close` releases everything (idempotent; after an error in
    :meth:`open` too).

    ``base`` is the flight every drone shares (robot kind, catalog, plugins, world, time limit); each drone's files
    go to ``<output>/<drone>/``. ``listen``: the router's endpoints (a free TLS port on 127.0.0.1 by default);
    ``connect``: join the fleet's router there instead. ``workers`` > 1 spreads the drones over that many worker
    processes (``lines`` hears their event lines); ``token``: the fleet's when its file names none (else a new
    one). ``notify`` hears one-line messages for the operator, ``report`` each problem a mission's check finds."""

    def __init__(self, fleet: Any, base: FlightSpec, *, output: str | Path | None = None,
                 listen: Sequence[str] = (), connect: Sequence[str] = (), workers: int = 1,
                 speed: float | None = None, token: str | None = None, remote_questions: bool = False,
                 recording: str | None = None, quiet: bool = False, verbose: bool = False,
                 lines: Callable[[str], None] = print, notify: Callable[[str], None] = logger.warning,
                 report: Callable[[Problem], None] = lambda problem: logger.warning("%s", problem)) -> None:
        self.spec, self.base, self.output = fleet, base, output
        self.listen, self.connect, self.workers = list(listen), list(connect), workers
        self.speed, self.remote_questions, self.recording_path = speed, remote_questions, recording
        self.quiet, self.verbose = quiet, verbose
        self.lines, self.notify, self.report = lines, notify, report
        self.token = fleet.token or token or secrets.token_hex(16)
        self.folder: Path | None = None
        self.membership: Any = None  # the fleet's router here, or the drones' sessions through it
        self.node: Any = None  # this process's node in the fleet (drones flown here)
        self.flight: FleetFlight | None = None  # the drones in this process
        self.worker_fleet: Any = None  # the drones in worker processes (a WorkerFleet)
        self.outcomes: dict[str, FlightOutcome] = {}  # each drone's outcome, drones flown in this process
        self._opened = self._closed = False

    # -- set-up ------------------------------------------------------------------------------------------------------
    def __enter__(self) -> FleetSession:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def endpoints(self) -> list[str]:
        """Where the fleet's router is reached (once opened)."""
        return list(self.membership.endpoints) if self.membership is not None else []

    @property
    def recording(self) -> Any:
        """The MCAP recording written while flying (``recording``), None when none."""
        return self.flight.recording if self.flight is not None else None

    def open(self) -> FleetSession:
        """Set the fleet up; raises (closing what was opened) when it cannot fly."""
        if self._opened:
            return self
        self._opened = True
        try:
            self._open()
        except BaseException:
            self.close()
            raise
        return self

    def _open(self) -> None:
        from aeroexec.fleet import members
        from aeroexec.fleet.fleet_json import write_fleet_file
        from aeroexec.fleet.transport import free_endpoint

        spec = self.spec
        self.folder = prepare_output(self.output)
        if self.connect:
            self.membership = members.connect(spec, self.connect)
        else:
            self.membership = members.listen(spec, self.listen or [free_endpoint("tls")], self.folder)
        write_fleet_file(self.folder, spec.name, self.endpoints, self.token, self.membership.operator,
                         (d.name for d in spec.drones))
        if self.workers > 1:
            from aeroexec.flight.fleet.workers import WorkerFleet

            self.worker_fleet = WorkerFleet(spec, self.base, workers=self.workers, endpoint=self.endpoints[0],
                                            token=self.token,
                                            credentials=members.credentials_folder(spec, self.folder),
                                            output=self.folder, speed=self.speed, quiet=self.quiet,
                                            verbose=self.verbose, lines=self.lines, notify=self.notify)
            self.worker_fleet.open()
            return
        self.node = self.membership.node(self.token)
        self.flight = FleetFlight(self.node, list(spec.flown), self.base, output=self.folder, speed=self.speed,
                                  telemetry_rate=spec.telemetry_rate, remote_questions=self.remote_questions,
                                  notify=self.notify, report=self.report, recording=self.recording_path)
        self.flight.open()

    def serve_console(self, port: int, host: str = "127.0.0.1") -> None:
        """Serve the web console of the drones flown in this process."""
        if self.flight is None:
            raise RuntimeError("the web console shows drones flown in this process: open the fleet with workers=1")
        self.flight.serve_console(port, host)

    # -- the flight --------------------------------------------------------------------------------------------------
    def fly(self) -> dict[str, dict[str, Any]]:
        """Fly every drone until each flight has ended (Ctrl-C, SIGTERM, SIGHUP and the time limit land every one);
        each drone's record of ``fleet_status.json`` with its ``summary`` line, in the fleet file's order."""
        if self.worker_fleet is not None:
            return self.worker_fleet.fly()
        if self.flight is None:
            raise RuntimeError("open() the fleet before flying it")
        self.outcomes = self.flight.fly()
        return {m.name: {**drone_status(self.outcomes[m.name]), "summary": summary_line(m, self.outcomes[m.name])}
                for m in self.flight.members}

    def close(self) -> None:
        """End every drone's flight, the workers, this process's node and the fleet's membership; ``fleet.json``
        removed (idempotent, never raises for what is already closed)."""
        if self._closed:
            return
        self._closed = True
        try:
            if self.worker_fleet is not None:
                self.worker_fleet.close()
            if self.flight is not None:
                self.flight.close()
        finally:
            try:
                if self.node is not None:
                    self.node.close()
            finally:
                if self.membership is not None:
                    self.membership.close()
                if self.folder is not None and self.membership is not None:
                    from aeroexec.fleet.fleet_json import FLEET_FILE

                    (self.folder / FLEET_FILE).unlink(missing_ok=True)


__all__ = ["FleetSession"]
