"""Reading a run's flight journal (read-only, while the run flies too): its segments, what happened to a behavior,
when a belief changed, which items of the mission are done, where it stopped, and the records of ``events.jsonl``
rebuilt from it (the report and the console's replay read a journal as they read an event log)."""

from __future__ import annotations

import functools
import json
import sqlite3
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from aeroexec.beliefs import BeliefError, parse_belief, parse_term
from aeroexec.beliefs.terms import match
from aeroexec.flight.flight_log import FORMAT as LOG_FORMAT
from aeroexec.flight.flight_log import read_flight_log
from aeroexec.flight.journal.schema import JournalError, connect, journal_path


@dataclass(frozen=True)
class Segment:
    """One process that flew the run (1: as started; then each resume)."""

    segment: int
    started_wall: str
    started_at: float
    live_at: float | None
    ended_at: float | None
    status: str | None  # None: it never ended (the process was killed, or still flies)
    exit_status: int | None
    reasons: list[str]


def _damage_said(method: Callable[..., Any]) -> Callable[..., Any]:
    """A question over the journal whose answer a damaged journal breaks: JournalError naming the file."""
    @functools.wraps(method)
    def asked(self: Journal, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except (ValueError, TypeError, KeyError, IndexError, AttributeError) as error:
            raise JournalError(f"{self.path}: the journal is damaged: {type(error).__name__}: {error}") from None

    return asked


class Journal:
    """A run's journal (``folder``: the run's output folder, or the journal file)."""

    def __init__(self, folder: str | Path) -> None:
        self.path = journal_path(folder)
        self.db = connect(self.path, readonly=True)
        self.db.row_factory = sqlite3.Row

    def __enter__(self) -> Journal:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.db.close()

    def rows(self, sql: str, params: tuple = ()) -> list[sqlite3.Row]:
        """The rows of a query (the journal is opened read-only: a query cannot change it)."""
        try:
            return self.db.execute(sql, params).fetchall()
        except (sqlite3.Error, UnicodeDecodeError) as error:  # a damaged journal, or a query it cannot answer
            raise JournalError(f"{self.path}: the journal cannot be read so: {error}") from None

    # -- the run -----------------------------------------------------------------------------------------------
    @_damage_said
    def meta(self) -> dict[str, Any]:
        found: dict[str, Any] = {}
        for row in self.rows("SELECT key, value FROM meta"):
            try:
                found[row["key"]] = json.loads(row["value"])
            except ValueError:
                found[row["key"]] = row["value"]
        return found

    @_damage_said
    def segments(self) -> list[Segment]:
        return [Segment(r["segment"], r["started_wall"], r["started_at"], r["live_at"], r["ended_at"], r["status"],
                        r["exit_status"], self.json(r["reasons"]) if r["reasons"] else [])
                for r in self.rows("SELECT * FROM segments ORDER BY segment")]

    def json(self, text: Any) -> Any:
        """A JSON value of the journal; JournalError when it is not one (a damaged journal)."""
        try:
            return json.loads(text)
        except (TypeError, ValueError) as error:
            raise JournalError(f"{self.path}: the journal is damaged: {error}") from None

    def progress(self, segment: int, key: str) -> tuple[int, float, Any] | None:
        """``(seq, time, value)`` of a segment's ``tree`` or ``stop`` (the value read from its JSON), or None."""
        row = self.rows("SELECT seq, time, value FROM progress WHERE segment = ? AND key = ?", (segment, key))
        if not row:
            return None
        value = row[0]["value"]
        return row[0]["seq"], row[0]["time"], self.json(value) if key == "stop" else value

    def last_time(self) -> float:
        """The latest engine time anything was journaled at."""
        times = [self.rows(f"SELECT max({column}) FROM {table}")[0][0]
                 for table, column in (("events", "time"), ("calls", "returned_at"), ("segments", "started_at"))]
        return max((t for t in times if t is not None), default=0.0)

    @_damage_said
    def last_state(self, segment: int | None = None, before: int | None = None) -> dict[str, Any] | None:
        """The drone's last journaled state (of ``segment``; before ``seq`` ``before``), or None."""
        clauses, params = [], []
        if segment is not None:
            clauses.append("segment = ?")
            params.append(segment)
        if before is not None:
            clauses.append("seq <= ?")
            params.append(before)
        where = f"WHERE {' AND '.join(clauses)}" if clauses else ""
        row = self.rows(f"SELECT * FROM telemetry {where} ORDER BY seq DESC LIMIT 1", tuple(params))
        if not row:
            return None
        r = row[0]
        return {"time": r["time"], "position": [r["x"], r["y"], r["z"]], "velocity": [r["vx"], r["vy"], r["vz"]],
                "yaw": r["yaw"], "battery": r["battery"], "armed": bool(r["armed"]), "landed_state": r["landed_state"]}

    # -- questions -------------------------------------------------------------------------------------------
    def behavior(self, name: str) -> list[sqlite3.Row]:
        """Every request of behavior ``name`` (case does not matter), in order: when, from whom, how it ended."""
        return self.rows("SELECT * FROM behaviors WHERE behavior = ? ORDER BY seq", (name.upper(),))

    @_damage_said
    def belief_changes(self, text: str) -> list[sqlite3.Row]:
        """Every change of the beliefs of a predicate (``charge``) or matching a belief pattern (``charge(battery,
        ?X)``: variables match anything), in order."""
        predicate = text.split("(", 1)[0].strip()
        rows = self.rows("SELECT * FROM beliefs WHERE predicate = ? ORDER BY seq", (predicate,))
        if "(" not in text:
            return rows
        try:
            pattern = parse_term(text)
        except BeliefError as error:
            raise JournalError(f"{text}: not a belief pattern ({error})") from None
        return [r for r in rows if match(pattern, parse_belief(r["belief"]), {})]

    @_damage_said
    def done(self) -> list[dict[str, Any]]:
        """The mission's steps that are done, in the order they were done: a tree's behavior leaves (a plan's
        items) that ended SUCCESS, a Python mission's behaviors whose goal was achieved; the latest run of each."""
        kind = self.meta().get("kind")
        if kind == "tree":
            rows = self.rows("SELECT t.* FROM node_transitions t WHERE t.new = 'SUCCESS' AND t.type IN "
                             "(SELECT DISTINCT behavior FROM behaviors WHERE source = 'mission') ORDER BY t.seq")
            latest: dict[Any, dict[str, Any]] = {}
            for r in rows:
                latest.pop(r["uid"], None)
                latest[r["uid"]] = {"time": r["time"], "segment": r["segment"], "step": r["node"],
                                    "behavior": r["type"], "line": r["line"]}
            return list(latest.values())
        rows = self.rows("SELECT * FROM behaviors WHERE source = 'mission' AND outcome = 'GOAL_ACHIEVED' "
                         "ORDER BY ended_seq")
        return [{"time": r["ended_at"], "segment": r["segment"], "step": r["behavior"], "behavior": r["behavior"],
                 "arguments": self.json(r["arguments"])} for r in rows]

    @_damage_said
    def goals(self) -> dict[str, int]:
        """How many times each goal of the mission was achieved over every segment: ``BEHAVIOR(arguments)`` ->
        count (GOAL_ACHIEVED of the mission's own requests)."""
        counts: dict[str, int] = {}
        for r in self.rows("SELECT behavior, arguments FROM behaviors WHERE source = 'mission' AND "
                           "outcome = 'GOAL_ACHIEVED' ORDER BY seq"):
            key = f"{r['behavior']}({r['arguments']})"
            counts[key] = counts.get(key, 0) + 1
        return counts

    # -- as an event log -------------------------------------------------------------------------------------
    @_damage_said
    def records(self) -> list[dict[str, Any]]:
        """The run as the records of its event log (``events.jsonl``): ``log_started`` with what the run was given,
        the events, the belief changes (but the drone's own motion) and the state samples, in order."""
        meta = dict(self.meta().get("log") or {})
        merged = [(r["seq"], r["segment"], self.json(r["record"]))
                  for r in self.rows("SELECT seq, segment, record FROM events ORDER BY seq")]
        records: list[dict[str, Any]] = []
        parts = {part.segment: part for part in self.segments()}
        for segment, part in parts.items():  # each part as its own stretch of the log, as events.jsonl has it
            kind = "log_started" if segment == 1 else "log_resumed"
            records.append({"time": part.started_at, "kind": kind, "format": LOG_FORMAT, **meta,
                            **({"segment": segment} if segment > 1 else {})})
            records.extend(record for _, of, record in merged if of == segment)
            if part.status is not None:
                records.append({"time": part.ended_at, "kind": "log_closed"})
        return records


def is_journal(path: str | Path) -> bool:
    """Whether ``path`` is a run's journal, or a folder holding one."""
    path = Path(path)
    found = path / "journal.sqlite" if path.is_dir() else path
    try:
        with open(found, "rb") as file:
            return file.read(16) == b"SQLite format 3\x00"
    except OSError:
        return False


def read_records(path: str | Path) -> list[dict[str, Any]]:
    """The records of a run's event log (``path``: an event log, a journal, or a run's folder: its events.jsonl,
    else its journal), the journal's rebuilt as the log has them; ValueError naming the file when unreadable."""
    path = Path(path)
    log = path / "events.jsonl" if path.is_dir() else path
    if not log.is_file() and path.is_dir() and is_journal(path) or is_journal(log):
        try:
            with Journal(path) as journal:
                return journal.records()
        except JournalError as error:
            raise ValueError(str(error)) from None
    return read_flight_log(log)


__all__ = ["Journal", "Segment", "is_journal", "read_records"]
