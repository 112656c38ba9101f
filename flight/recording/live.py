"""A recording written while the run flies (``aeroexec run --mcap FILE``, and the live view ``--foxglove``): the
event log's lines, as the log writes them at the end of each tick, are handed to a thread of their own
(``aeroexec-recording``), which makes them messages with the same
:class:`~aeroexec.flight.recording.recorder.Recorder` an export uses, once for every sink (the file, the view); so a
flight's live recording holds what ``aeroexec export`` makes of its log afterwards, message for message. The
engine's loop only queues bytes; a recording that cannot be written (a full disk) is said once and given up, the
flight goes on.
"""

from __future__ import annotations

import json
import logging
import queue
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from aeroexec.flight.recording.export import route_of, standing
from aeroexec.flight.recording.recorder import Recorder, Sink, start_ns
from aeroexec.flight.recording.topics import Drone

logger = logging.getLogger(__name__)


@dataclass
class _Fed:
    """A drone whose event log feeds the recording: its frame, its log's first record, its mission file (the
    planned route is read from it when its first state sample says where the drone stands)."""

    drone: Drone
    header: dict[str, Any]
    mission: Path | None
    route_pending: bool


class LiveRecording:
    """The recording of a flight to ``sinks`` (an MCAP file, a live view), fed by the event log writer of each
    drone (:meth:`attach`: one for a run, every drone of a fleet flown in this process); :meth:`close` after the
    logs are closed writes what is left and finishes the file."""

    def __init__(self, sinks: list[Sink], path: str | Path | None = None) -> None:
        """``path``: the MCAP file among the sinks, named in messages."""
        self.path = Path(path) if path is not None else None
        self.recorder = Recorder(sinks)
        self.error: str | None = None  # why the recording was given up, None while it is whole
        self._queue: queue.SimpleQueue[tuple[int, bytes]] = queue.SimpleQueue()
        self._fed: list[_Fed] = []
        self._thread = threading.Thread(target=self._run, name="aeroexec-recording", daemon=True)
        self._thread.start()

    def attach(self, flight_log: Any, mission: Path | None = None) -> None:
        """Record what ``flight_log`` (a :class:`~aeroexec.flight.flight_log.FlightLogWriter`) writes from now on,
        its first record (``log_started``) saying whose flight it is; the planned route from ``mission``."""
        header = dict(flight_log.header)
        home = header.get("home")
        drone = Drone(str(header.get("drone_name") or "drone"),
                      tuple(float(v) for v in home) if isinstance(home, list) and len(home) == 3 else None,
                      start_ns(self._fed[0].header if self._fed else header))  # one clock for a fleet
        if any(fed.drone.name == drone.name for fed in self._fed):
            raise ValueError(f"two drones named {drone.name} in one recording")
        self._fed.append(_Fed(drone, header, mission, mission is not None))
        self.recorder.declare(drone)
        index = len(self._fed) - 1
        flight_log.taps.append(lambda data: self._queue.put((index, data)))

    def _run(self) -> None:
        while True:
            index, data = self._queue.get()
            if index < 0:
                return
            if self.error is not None:
                continue
            try:
                for line in data.decode("utf-8").splitlines():
                    self._record(self._fed[index], json.loads(line))
            except Exception as error:  # the disk, a bug: the recording stops, the flight goes on
                self.error = f"{type(error).__name__}: {error}"
                logger.error("the recording %s stops here (%s); the flight goes on", self.path or "", self.error)

    def _record(self, fed: _Fed, record: dict[str, Any]) -> None:
        if fed.route_pending and record.get("kind") == "state":  # the route from where the drone stands
            fed.route_pending = False
            points = route_of(fed.mission, standing([record])) if fed.mission else None
            if points is not None:
                self.recorder.record(fed.drone, {"time": fed.header.get("time", 0.0), "kind": "route",
                                                 "points": [list(p) for p in points]})
        self.recorder.record(fed.drone, record)

    def close(self) -> None:
        """Write what the logs wrote last and finish the file (a recording given up is removed; its error stays)."""
        if self._thread.is_alive():
            self._queue.put((-1, b""))
            self._thread.join()
        if self._fed and self.error is None:
            first = self._fed[0].header
            self.recorder.metadata("aeroexec", {"mission": first.get("mission", ""), "clock": first.get("clock", ""),
                                                "drones": ",".join(f.drone.name for f in self._fed),
                                                "fleet": first.get("fleet", ""),
                                                "start_ns": self._fed[0].drone.start_ns})
        self.recorder.close(keep=self.error is None and bool(self._fed))  # nothing flew: no file

    def recorded(self, topic: str) -> int:
        """How many messages went to ``topic`` so far."""
        return self.recorder.counts[topic]


__all__ = ["LiveRecording"]
