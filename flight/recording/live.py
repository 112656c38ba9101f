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
from pathlib import Path
from typing import Any

from aeroexec.flight.recording.export import route_of
from aeroexec.flight.recording.recorder import Recorder, Sink, start_ns
from aeroexec.flight.recording.topics import Drone

logger = logging.getLogger(__name__)
_END = b""


class LiveRecording:
    """The recording of one drone's flight to ``sinks`` (an MCAP file, a live view), fed by its event log writer
    (:meth:`attach`); :meth:`close` after the log is closed writes what is left and finishes the file."""

    def __init__(self, sinks: list[Sink], mission: Path | None = None, path: str | Path | None = None) -> None:
        """``path``: the MCAP file among the sinks, named in messages."""
        self.path = Path(path) if path is not None else None
        self.mission = mission  # where the planned route is read from (None: no route)
        self.recorder = Recorder(sinks)
        self.error: str | None = None  # why the recording was given up, None while it is whole
        self._queue: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        self._drone: Drone | None = None
        self._header: dict[str, Any] = {}
        self._route_pending = mission is not None
        self._thread = threading.Thread(target=self._run, name="aeroexec-recording", daemon=True)
        self._thread.start()

    def attach(self, flight_log: Any) -> None:
        """Record what ``flight_log`` (a :class:`~aeroexec.flight.flight_log.FlightLogWriter`) writes from now on,
        its first record (``log_started``) saying whose flight it is."""
        header = dict(flight_log.header)
        name = str(header.get("drone_name") or "drone")
        home = header.get("home")
        self._header = header
        self._drone = Drone(name, tuple(float(v) for v in home) if isinstance(home, list) and len(home) == 3 else None,
                            start_ns(header))
        self.recorder.metadata("aeroexec", {"mission": header.get("mission", ""), "clock": header.get("clock", ""),
                                            "drones": name, "fleet": header.get("fleet", ""),
                                            "start_ns": self._drone.start_ns})
        self.recorder.declare(self._drone)
        flight_log.taps.append(self._queue.put)

    def _run(self) -> None:
        while True:
            data = self._queue.get()
            if data is _END:
                return
            if self.error is not None or self._drone is None:
                continue
            try:
                for line in data.decode("utf-8").splitlines():
                    self._record(json.loads(line))
            except Exception as error:  # the disk, a bug: the recording stops, the flight goes on
                self.error = f"{type(error).__name__}: {error}"
                logger.error("the recording %s stops here (%s); the flight goes on", self.path or "", self.error)

    def _record(self, record: dict[str, Any]) -> None:
        assert self._drone is not None
        if self._route_pending and record.get("kind") == "state":  # the route from where the drone stands
            self._route_pending = False
            position = record.get("position") or [0.0, 0.0]
            points = route_of(self.mission, (float(position[0]), float(position[1]))) if self.mission else None
            if points is not None:
                self.recorder.record(self._drone, {"time": self._header.get("time", 0.0), "kind": "route",
                                                   "points": [list(p) for p in points]})
        self.recorder.record(self._drone, record)

    def close(self) -> None:
        """Write what the log wrote last and finish the file (a recording given up is removed; its error stays)."""
        if self._thread.is_alive():
            self._queue.put(_END)
            self._thread.join()
        self.recorder.close(keep=self.error is None and self._drone is not None)  # nothing flew: no file

    def recorded(self, topic: str) -> int:
        """How many messages went to ``topic`` so far."""
        return self.recorder.counts[topic]


__all__ = ["LiveRecording"]
