"""The event log file of a run: one JSON object per line, written at the end of every engine tick, so a crash loses
at most the tick it happened in.

Every line has ``time`` (engine seconds) and ``kind``. The kinds:

- ``log_started`` (first line): ``format``, ``clock`` (``simulated`` or ``wall``), ``wall_time`` (ISO 8601 to the
  millisecond, at the line's ``time``; only on the wall clock, so a simulated run's log is the same in every
  replay) and what the run was given (``mission``, ``world``, ``drone``...).
- an engine event (``activated``, ``GOAL_ACHIEVED``, ``rejected``, ``node_status``...): ``behavior``, ``detail``,
  and when the event has them ``arguments`` (of an activation), ``result`` (of a deliberative behavior),
  ``reason`` (why a behavior ended, was rejected or failed: the event's message); the rest of the event's data
  under ``data``.
- ``belief_added`` / ``belief_removed``: ``belief`` (its text in the belief language) and ``reason`` (add,
  remove, replaced, expired, clear).
- ``state``: a drone state sample (``position`` and ``velocity`` ENU, ``yaw`` degrees, ``battery`` percent,
  ``armed``, ``landed_state``), every ``sample_period`` seconds of engine time (2 Hz by default).
- ``log_closed`` (last line, only when the run ended normally and every record was written).
- ``log_resumed``: a resumed run (``aeroexec run --resume``) goes on in the same log: this line (``segment``: 2 for
  the first resume, then 3...) and what the run was given, then its records, their times going on from where the
  interrupted run stopped.

A tick's lines are written with one ``write`` system call on an unbuffered file (more for a short write), so a
killed process leaves whole lines but for the last, which a reader ignores and a resumed run cuts off. When
lines cannot be written whole (the disk is full, the file system is gone), what was written of a line is cut
off again and nothing more is written: the log ends at a record boundary, :attr:`incomplete` says why, the lines
not written are counted in :attr:`lost`, and the error is logged once. :func:`read_flight_log` reads a log back
(ignoring a torn last line, should there be one).
"""

from __future__ import annotations

import contextlib
import datetime
import enum
import json
import logging
import math
import os
import threading
from collections.abc import Callable
from pathlib import Path

from aeroexec.beliefs import BeliefChange, Struct, format_term
from aeroexec.engine.clock import SimulatedClock
from aeroexec.engine.events import EngineEvent, Outcome

from aeroexec.compact_json import compact_encoder
from aeroexec.limits import MAX_NESTING, InputError, nesting_beyond, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

FORMAT = "aeroexec-events/1"
SAMPLE_PERIOD = 0.5  # s of engine time between drone state samples
PENDING = 4096  # lines kept for the end of the tick at most: more are written at once
#: Event kinds whose message is the reason a behavior ended or did not start.
REASON_KINDS = {o.value for o in Outcome} | {"failed_preconditions", "rejected", "mission_failed", "process_failed"}


class FlightLogWriter:
    """Writes ``engine``'s events, belief changes and drone state samples to ``path`` until :meth:`close`."""

    def __init__(self, engine: Any, path: str | Path, sample_period: float = SAMPLE_PERIOD,
                 meta: dict[str, Any] | None = None, resumed: int | None = None) -> None:
        """``resumed``: the segment of a resumed run, whose records go on after the interrupted run's (a
        ``log_resumed`` line first) instead of starting a new log."""
        self.engine = engine
        self._clock = engine.clock  # the engine's time (Engine.now, without its call)
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.sample_period = sample_period
        self._lock = threading.Lock()
        if resumed is not None:
            _cut_torn_line(self.path)
        self._fd: int | None = os.open(self.path, os.O_WRONLY | os.O_CREAT |
                                       (os.O_APPEND if resumed is not None else os.O_TRUNC), 0o644)
        self._end = os.lseek(self._fd, 0, os.SEEK_END)  # where the next line goes (the writer is alone)
        self._pending: list[str] = []  # the tick's lines (without their ends), written at its end, encoded once
        self._texts: dict[str, tuple[tuple, str]] = {}  # predicate -> the arguments last added, and their text
        self._last_sample: float | None = None
        self.lines = 0
        #: Why records were lost (the write error), or None while every record is in the file.
        self.incomplete: str | None = None
        self.lost = 0  # records that could not be written
        self._final: tuple[int, int] | None = None  # where the run's last records start (see :meth:`last_records`)
        #: Called with each block of whole lines written (a recording written while flying), under the lock.
        self.taps: list[Callable[[bytes], None]] = []
        header: dict[str, Any] = {"time": round(engine.now(), 3), "kind": "log_started", "format": FORMAT}
        if resumed is not None:
            header.update(kind="log_resumed", segment=resumed)
        if isinstance(getattr(engine, "clock", None), SimulatedClock):
            header["clock"] = "simulated"
        else:
            header["clock"] = "wall"
            header["wall_time"] = datetime.datetime.now().astimezone().isoformat(timespec="milliseconds")
        self.header: dict[str, Any] = {**header, **{k: plain(v) for k, v in (meta or {}).items()}}  # the first line
        self._write(self.header)
        self.flush()
        self._unsubscribe = [engine.log.subscribe(self.on_event), engine.memory.subscribe(self.on_belief)]
        engine.tick_callbacks.append(self.on_tick)

    # -- listeners ---------------------------------------------------------------------------------
    def on_event(self, event: EngineEvent) -> None:
        self._write_line(event_line(event))

    def on_belief(self, change: BeliefChange) -> None:
        if change.reason == "shared":  # a fleet mate's position came or went: its fleet_drone_heard event says so
            return
        self._write_line(belief_line(change, self._texts))

    def on_tick(self) -> None:
        now = self._clock.now()
        last = self._last_sample
        if last is None or now - last >= self.sample_period - 1e-9:
            self.sample(now)
        if self._pending:  # as flush(), without its call: the end of every period of every drone
            with self._lock:
                self._write_pending()

    def sample(self, now: float | None = None) -> None:
        """Write the drone's state now."""
        now = self.engine.now() if now is None else now
        self._last_sample = now
        try:
            telemetry = self.engine.drone.telemetry()
        except Exception:  # a drone that cannot answer: no sample, the log goes on
            logger.exception("no drone state for the event log")
            return
        self._write_line(state_line(now, telemetry))

    # -- the file ----------------------------------------------------------------------------------
    def _write(self, record: dict[str, Any]) -> None:
        self._write_line(_json(record))

    def _write_line(self, line: str) -> None:
        with self._lock:
            if self._fd is None:
                return
            if self.incomplete is not None:
                self.lost += 1
                return
            pending = self._pending
            pending.append(line)
            if len(pending) >= PENDING:
                self._write_pending()

    def flush(self) -> None:
        """Write the lines kept since the last tick."""
        if not self._pending:  # nothing since the last tick (a line added meanwhile is the next flush's)
            return
        with self._lock:
            self._write_pending()

    def _write_pending(self) -> None:
        lines, self._pending = self._pending, []
        if not lines or self._fd is None:
            return
        lines.append("")  # the last line's end
        data = "\n".join(lines).encode("utf-8")
        lines.pop()
        written = 0
        try:
            written = os.write(self._fd, data)
            while written < len(data):  # a short write (a full disk, a signal): finish the lines
                written += os.write(self._fd, data[written:])
        except OSError as exc:
            whole = data.rfind(b"\n", 0, written) + 1  # the lines written whole stay
            kept = data.count(b"\n", 0, whole)
            self._end += whole
            self.lines += kept
            self._stop_writing(exc, len(lines) - kept)
            self._tap(data[:whole])
            return
        self._end += len(data)
        self.lines += len(lines)
        if self.taps:
            self._tap(data)

    def _tap(self, data: bytes) -> None:
        for tap in self.taps:
            if data:
                tap(data)

    def last_records(self) -> None:
        """What is recorded from now on (the run's end, ``log_closed``) is written whole or not at all: every
        record before is written now, and a write that fails later cuts the log back to here, so a log that says
        how the run ended (``run_ended``, with its exit status) is a whole log."""
        self.flush()
        with self._lock:
            if self.incomplete is None:
                self._final = (self._end, self.lines)

    def _stop_writing(self, error: OSError, lost: int) -> None:
        """Lines could not be written whole: cut off what was of the first of them (the log ends at a record
        boundary; back to :meth:`last_records`' mark once it is set), write nothing more, and say so once."""
        self.incomplete = error.strerror or str(error)
        self.lost += lost
        if self._final is not None and self._end > self._final[0]:
            self.lost += self.lines - self._final[1]
            self._end, self.lines = self._final
        with contextlib.suppress(OSError):
            os.ftruncate(self._fd, self._end)
            os.lseek(self._fd, self._end, os.SEEK_SET)
        logger.error("the event log %s cannot be written (%s): it stops after %d records; the flight goes on",
                     self.path, self.incomplete, self.lines)

    def close(self) -> None:
        """A last state sample, ``log_closed``, then the file is synced and closed (idempotent)."""
        if self._fd is None:
            return
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        if self.on_tick in self.engine.tick_callbacks:
            self.engine.tick_callbacks.remove(self.on_tick)
        self.sample()
        self.flush()
        self._write({"time": round(self.engine.now(), 3), "kind": "log_closed", "lines": self.lines + 1})
        with self._lock:
            self._write_pending()
            fd, self._fd = self._fd, None
        with contextlib.suppress(OSError):
            os.fsync(fd)
        os.close(fd)

    def __enter__(self) -> FlightLogWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _cut_torn_line(path: Path) -> None:
    """Cut a last line left without its end (a killed process) off the log, so what follows starts a line."""
    try:
        with open(path, "rb+") as file:
            size = file.seek(0, os.SEEK_END)
            if size == 0:
                return
            tail = max(0, size - (1 << 16))
            file.seek(tail)
            data = file.read()
            if data.endswith(b"\n"):
                return
            end = data.rfind(b"\n")
            file.truncate(tail + end + 1 if end >= 0 else tail)
    except FileNotFoundError:
        pass


class _Lines:
    """The last line made of each kind of record, so the event log and the flight journal, hearing the same event,
    belief change or sample one after the other, make it once."""

    def __init__(self) -> None:
        self.event: tuple[Any, str] = (None, "")
        self.belief: tuple[Any, str] = (None, "")
        self.state: tuple[tuple[Any, Any], str] = ((None, None), "")
        self.time: tuple[Any, str] = (None, "")  # the last belief change's time (the very object), and its text


_LINES = _Lines()


def event_line(event: EngineEvent) -> str:
    """An event's line in the log (JSON, without its end)."""
    last, line = _LINES.event
    if last is not event:
        line = _json(event_record(event))
        _LINES.event = (event, line)
    return line


def belief_line(change: BeliefChange, texts: dict[str, tuple[tuple, str]] | None = None) -> str:
    """A belief change's line in the log (``belief_added`` / ``belief_removed``: the belief's text, the reason).
    ``texts``: a writer's last added arguments and text of each predicate, so a value replaced (an exclusive
    belief: a position, a speed) is removed with the text it was added with, not formatted again."""
    last, line = _LINES.belief
    if last is not change:
        belief = change.belief
        known = texts.get(belief.name) if texts is not None else None
        if known is not None and known[0] is belief.args:
            text = known[1]
        else:
            text = _text(flat_text(belief))
            if texts is not None and change.kind == "added":
                texts[belief.name] = (belief.args, text)
        at, stamp = _LINES.time
        if change.time is not at:  # the changes of a period (of every drone of a fleet) share the clock's time
            stamp = _number(round(float(change.time), 3))
            _LINES.time = (change.time, stamp)
        # as _json writes the record, without building it: the log's most frequent line (ordered keys, compact)
        line = (f'{{"time":{stamp},"kind":{_KINDS.get(change.kind) or _kind(change)},'
                f'"belief":{text},"reason":{_REASONS.get(change.reason) or _text(change.reason)}}}')
        _LINES.belief = (change, line)
    return line


def flat_text(term: Struct) -> str:
    """:func:`~aeroexec.beliefs.format_term` of a belief, the same text, made faster for what telemetry writes:
    arguments that are numbers, atoms and tuples of floats (anything else is formatted by ``format_term``)."""
    args = term.args
    if len(args) == 2 and type(args[0]) is str:  # of one thing (self, a drone): what telemetry writes, made at once
        first = _ATOMS.get(args[0])
        if first is not None:
            value = args[1]
            kind = type(value)
            if kind is float:
                return f"{term.name}({first}, {value!r})"
            if kind is tuple and len(value) == 3:
                x, y, z = value
                if type(x) is float and type(y) is float and type(z) is float:
                    return f"{term.name}({first}, ({x!r}, {y!r}, {z!r}))"
            elif kind is int:
                return f"{term.name}({first}, {value})"
            elif kind is str:
                second = _ATOMS.get(value)
                if second is not None:
                    return f"{term.name}({first}, {second})"
    if not args:
        return format_term(term)
    parts = []
    for arg in args:
        kind = type(arg)
        if kind is float:
            parts.append(repr(arg))
        elif kind is int:
            parts.append(str(arg))
        elif kind is str:
            atom = _ATOMS.get(arg)
            if atom is None:
                atom = format_term(arg)
                if len(_ATOMS) < 4096:
                    _ATOMS[arg] = atom
            parts.append(atom)
        elif kind is tuple and len(arg) == 3 and type(arg[0]) is float and type(arg[1]) is float \
                and type(arg[2]) is float:  # a position, a velocity: the most frequent argument
            parts.append(f"({arg[0]!r}, {arg[1]!r}, {arg[2]!r})")
        elif kind is tuple and len(arg) > 1 and all(type(v) is float for v in arg):
            parts.append("(" + ", ".join(map(repr, arg)) + ")")
        else:
            parts.append(format_term(arg))
    return term.name + "(" + ", ".join(parts) + ")"


_ATOMS: dict[str, str] = {}  # an atom's text (quoted when it must be), by the atom
_KINDS = {"added": '"belief_added"', "removed": '"belief_removed"'}
_REASONS = {reason: json.dumps(reason) for reason in ("add", "replaced", "remove", "expired", "clear")}


def _kind(change: BeliefChange) -> str:
    return _text("belief_" + change.kind)


def state_line(now: float, telemetry: Any) -> str:
    """A drone state sample's line in the log."""
    (at, sampled), line = _LINES.state
    # the very object (kept, not its id: another drone's telemetry made at the same time may get a freed one's id)
    if sampled is not telemetry or at != now:
        line = _json(state_record(now, telemetry))
        _LINES.state = ((now, telemetry), line)
    return line


#: ``json.dumps(record, allow_nan=False, separators=(",", ":"))``, the same text, by one encoder made once (an event or
#: sample line of every drone)
_json: Callable[[dict[str, Any]], str] = compact_encoder(allow_nan=False)


_text = json.encoder.encode_basestring_ascii  # a string as json.dumps writes it


def _number(value: float) -> str:
    """A finite float as json.dumps writes it (ValueError for NaN and infinities, as ``allow_nan=False``)."""
    if not math.isfinite(value):
        raise ValueError(f"Out of range float values are not JSON compliant: {value!r}")
    return float.__repr__(value)


def event_record(event: EngineEvent) -> dict[str, Any]:
    """An engine event as a log line's object."""
    data = dict(event.data)
    record: dict[str, Any] = {"time": round(event.time, 3), "kind": event.kind, "behavior": event.behavior,
                              "detail": event.detail}
    if "arguments" in data:
        record["arguments"] = plain(data.pop("arguments"))
    if data.get("result") is not None:
        record["result"] = plain(data.pop("result"))
    data.pop("result", None)
    if event.kind in REASON_KINDS:
        record["reason"] = event.detail
    if data:  # a value JSON holds as it is (most of them) is taken as it is
        record["data"] = {str(k): v if type(v) in _AS_IS else plain(v) for k, v in data.items()}
    return record


_AS_IS = frozenset({str, int, bool, type(None)})  # what plain() gives back unchanged (exactly these types)


def state_record(now: float, telemetry: Any) -> dict[str, Any]:
    """A drone state sample as a log line's object; ``measured`` is when the position came from a vehicle that
    reports it over a link (the engine reads it up to a stream period later)."""
    record = {"time": round(now, 3), "kind": "state",
              "position": [round(float(v), 3) for v in telemetry.position],
              "velocity": [round(float(v), 3) for v in telemetry.velocity],
              "yaw": round(float(telemetry.yaw), 2), "battery": round(float(telemetry.battery_percent), 2),
              "armed": bool(telemetry.armed), "landed_state": plain(telemetry.landed_state)}
    measured = getattr(telemetry, "position_time", None)
    if measured is not None:
        record["measured"] = round(float(measured), 3)
    return record


def plain(value: Any) -> Any:
    """``value`` as something JSON can hold (beliefs as their text, enums as their value, NaN as null)."""
    if isinstance(value, bool) or value is None or isinstance(value, int | str):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, enum.Enum):
        return plain(value.value) if isinstance(value.value, str | int | float) else value.name
    if isinstance(value, Struct):
        return format_term(value)
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, set | frozenset):  # sorted: a set's order changes with the process's string hashing
        return sorted((plain(v) for v in value), key=lambda v: json.dumps(v, sort_keys=True))
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    try:
        return plain(value.tolist())  # numpy values
    except AttributeError:
        return str(value)


#: Largest event log read back (``aeroexec report``, ``aeroexec beliefs``), in bytes.
MAX_LOG_BYTES = 1 << 30


def world_meta(world: Any) -> dict[str, Any]:
    """What the event log's first record says of the world: its home (latitude, longitude, altitude) and bounds."""
    if world is None:
        return {}
    meta: dict[str, Any] = {}
    home = getattr(world, "home", None)
    if home is not None:
        meta["home"] = [round(float(home[0]), 8), round(float(home[1]), 8), round(float(home[2]), 3)]
    bounds = getattr(world, "bounds", None)
    if bounds is not None:
        meta["bounds"] = [[float(v) for v in bounds.lower], [float(v) for v in bounds.upper]]
    return meta


def read_flight_log(path: str | Path) -> list[dict[str, Any]]:
    """The records of an event log; a last line cut short (by a crash mid-write) is left out."""
    return [record for _, record in read_numbered_log(path)]


def read_numbered_log(path: str | Path) -> list[tuple[int, dict[str, Any]]]:
    """The records of an event log with their line numbers (from 1), as :func:`read_flight_log` reads them."""
    records: list[tuple[int, dict[str, Any]]] = []
    try:
        lines = read_text(path, limit=MAX_LOG_BYTES).split("\n")  # a FIFO is refused unread
    except InputError as exc:  # the callers say "cannot read the event log" and the file
        raise ValueError(exc.message.removeprefix("cannot read the file: ")) from None
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            if nesting_beyond(line, MAX_NESTING, "[{", "]}", quotes='"') is not None:
                raise ValueError(f"{path}:{number}: nested more than {MAX_NESTING} levels deep")
            records.append((number, json.loads(line)))
        except json.JSONDecodeError:
            if number == len(lines):  # the torn last line (no newline after it)
                logger.warning("%s: the last line is incomplete and was left out", path)
                break
            raise ValueError(f"{path}:{number}: not a JSON object") from None
    return records
