"""The flight journal's database: one SQLite file per run, ``journal.sqlite`` in its output folder, in WAL mode.

Every row carries ``seq``, one sequence over the whole journal (the order things happened in, across tables), and
``segment``: 1 for the run as started, 2, 3... for each resume of it. Times are engine seconds; a resumed run's
clock goes on from where the interrupted one stopped, so times never go back. The tables:

- ``meta`` (key, value): ``format``, ``mission`` (the file), ``kind`` (python or tree), ``spec`` (the flight as
  asked, JSON), ``log`` (what the event log's first line says), ``tree_shape`` (a tree's nodes, JSON).
- ``segments``: one row per process that flew the run: ``started_wall``, ``started_at``, ``live_at`` (when its
  mission went live, after the replay and the rejoin; NULL: never), and, once it ended, ``ended_at``, ``status``
  (completed, suspended, failed...), ``exit_status``, ``reasons`` (JSON). A crash leaves them NULL.
- ``events``: the run's records as ``events.jsonl`` has them, ``record`` being the very line (JSON), with
  ``time``, ``kind``, ``behavior`` and ``detail`` as columns: every engine event; every belief change
  (``belief_added`` / ``belief_removed``, with ``expires_at``: the engine time a belief of a persistent predicate
  lapses) but the robot's own motion (``position``, ``speed``, ``orientation`` of ``self``, ten times a second),
  which the state samples carry; the drone's state samples (``state``: once a second, every other one of
  events.jsonl's, and when a behavior of the mission ends or the mission stops).
- views over it: ``beliefs`` (``change`` added/removed, ``belief`` as text, ``predicate``, ``reason``: add,
  remove, replaced, expired, clear; ``expires_at``) and ``telemetry`` (position and velocity, ENU m and m/s,
  ``yaw`` degrees, ``battery`` percent, ``armed``, ``landed_state``).
- ``behaviors``: one row per activation request: ``behavior``, ``arguments`` (JSON), ``source`` (mission,
  reactive, operator, resume), ``priority``, ``activated_at``, and how it ended: ``ended_at``, ``outcome``
  (GOAL_ACHIEVED, TIME_OUT, WRONG_PROGRESS, INTERRUPTED, FAILED_PRECONDITIONS), ``message``, ``result`` (JSON).
- ``calls``: a Python mission's API calls that act or wait, in order: ``number`` (from 1), ``function``,
  ``arguments`` and ``result`` (JSON, as ``engine/missions/values.py`` keeps values), ``error``, ``location``
  (file:line), ``requested_at``, ``returned_at`` (NULL: under way), ``after_stop`` (it returned after the mission
  was stopped), ``superseded`` (a resume made it again).
- ``looks``: the calls that only look (``consult_belief``, ``true_belief``, ``is_active_behavior``, ``now``) in
  runs, one row a run: its ``first`` call's number and ``count``, ``calls`` (JSON: each distinct call as
  ``[function, arguments, location, result]``) and ``sequence`` (zlib: a byte per call, the index of the distinct
  call it was), so a polling loop costs a few bytes, not a row per call; ``after_stop``, ``superseded``.
- ``progress`` (segment, key): ``tree``: the tree's last state (``trees/runtime/tree_state.py``, JSON); ``stop``:
  where and why the mission stopped (a safety reaction, ``ctl suspend``, an abort, the time limit), with the
  drone's state then.
- views ``node_transitions`` (a tree's node status changes) and ``operator_commands``.

No table has an index but its ``seq``, and what a tick adds goes to as few tables as can hold it: every table or
index a commit touches costs it a page more, for a journal of a few MB that reads fast whole.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import sqlite3
from pathlib import Path

NAME = "journal.sqlite"
FORMAT = "aeroexec-journal/1"

SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS segments (
    segment INTEGER PRIMARY KEY, started_wall TEXT NOT NULL, started_at REAL NOT NULL, live_at REAL,
    ended_at REAL, status TEXT, exit_status INTEGER, reasons TEXT);
CREATE TABLE IF NOT EXISTS events (
    seq INTEGER PRIMARY KEY, segment INTEGER NOT NULL, time REAL NOT NULL, kind TEXT NOT NULL,
    behavior TEXT NOT NULL, detail TEXT NOT NULL, record TEXT NOT NULL, expires_at REAL);
CREATE TABLE IF NOT EXISTS behaviors (
    seq INTEGER PRIMARY KEY, segment INTEGER NOT NULL, behavior TEXT NOT NULL, arguments TEXT NOT NULL,
    source TEXT NOT NULL, priority TEXT, activated_at REAL NOT NULL, ended_seq INTEGER, ended_at REAL,
    outcome TEXT, message TEXT, result TEXT);
CREATE TABLE IF NOT EXISTS calls (
    seq INTEGER PRIMARY KEY, segment INTEGER NOT NULL, number INTEGER NOT NULL, function TEXT NOT NULL,
    arguments TEXT NOT NULL, location TEXT NOT NULL, requested_at REAL NOT NULL, returned_at REAL, result TEXT,
    error TEXT, after_stop INTEGER NOT NULL DEFAULT 0, superseded INTEGER NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS looks (
    seq INTEGER PRIMARY KEY, segment INTEGER NOT NULL, first INTEGER NOT NULL, count INTEGER NOT NULL,
    calls TEXT NOT NULL, sequence BLOB NOT NULL, returned_at REAL, after_stop INTEGER NOT NULL DEFAULT 0,
    superseded INTEGER NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS progress (
    segment INTEGER NOT NULL, key TEXT NOT NULL, seq INTEGER NOT NULL, time REAL NOT NULL, value TEXT NOT NULL,
    PRIMARY KEY (segment, key));
CREATE VIEW IF NOT EXISTS beliefs AS
    SELECT seq, segment, time, substr(kind, 8) AS change, json_extract(record, '$.belief') AS belief,
           rtrim(substr(json_extract(record, '$.belief'), 1, instr(json_extract(record, '$.belief') || '(', '(') - 1))
               AS predicate,
           json_extract(record, '$.reason') AS reason, expires_at
    FROM events WHERE kind IN ('belief_added', 'belief_removed');
CREATE VIEW IF NOT EXISTS telemetry AS
    SELECT seq, segment, time, json_extract(record, '$.position[0]') AS x, json_extract(record, '$.position[1]') AS y,
           json_extract(record, '$.position[2]') AS z, json_extract(record, '$.velocity[0]') AS vx,
           json_extract(record, '$.velocity[1]') AS vy, json_extract(record, '$.velocity[2]') AS vz,
           json_extract(record, '$.yaw') AS yaw, json_extract(record, '$.battery') AS battery,
           json_extract(record, '$.armed') AS armed, json_extract(record, '$.landed_state') AS landed_state
    FROM events WHERE kind = 'state';
CREATE VIEW IF NOT EXISTS node_transitions AS
    SELECT seq, segment, time, json_extract(record, '$.data.uid') AS uid, json_extract(record, '$.data.node') AS node,
           json_extract(record, '$.data.type') AS type, json_extract(record, '$.data.line') AS line,
           json_extract(record, '$.data.old') AS old, json_extract(record, '$.data.new') AS new
    FROM events WHERE kind = 'node_status';
CREATE VIEW IF NOT EXISTS operator_commands AS
    SELECT seq, segment, time, json_extract(record, '$.data.command') AS command,
           json_extract(record, '$.data.argument') AS argument, json_extract(record, '$.data.origin') AS origin,
           json_extract(record, '$.data.ok') AS ok, detail
    FROM events WHERE kind = 'operator_command';
"""


class JournalError(Exception):
    """A journal that cannot be opened, read or written, in words naming the file; ``no_space``: its disk is full."""

    def __init__(self, message: str, no_space: bool = False) -> None:
        super().__init__(message)
        self.no_space = no_space


def disk_full(error: BaseException) -> bool:
    """Whether SQLite's ``error`` is a full disk (SQLITE_FULL: "database or disk is full")."""
    return getattr(error, "sqlite_errorcode", None) == sqlite3.SQLITE_FULL or "disk is full" in str(error)


def journal_path(folder: str | Path) -> Path:
    """The journal of the run whose output folder is ``folder`` (or ``folder`` itself when it names a file)."""
    folder = Path(folder)
    return folder if folder.suffix == ".sqlite" or folder.is_file() else folder / NAME


def connect(path: Path, *, readonly: bool = False) -> sqlite3.Connection:
    """A connection to the journal at ``path``: read-only (it must exist and be a journal), or for writing (made
    with its schema when new), in WAL mode, committing at every transaction's end without waiting for the disk
    (a killed process loses nothing committed; a power cut, at most the last commits)."""
    try:
        if readonly:
            if not path.is_file():
                raise JournalError(f"{path}: no flight journal here")
            connection = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True, timeout=5.0)
        else:
            connection = sqlite3.connect(path, timeout=5.0, check_same_thread=False)
            connection.execute("PRAGMA journal_mode=WAL")
            connection.execute("PRAGMA synchronous=NORMAL")
            connection.executescript(SCHEMA)
        found = connection.execute("SELECT value FROM meta WHERE key = 'format'").fetchone()
    except (sqlite3.DatabaseError, UnicodeDecodeError) as error:
        if not readonly and disk_full(error):
            raise JournalError(f"{path}: no space left to write the journal ({error})", no_space=True) from None
        raise JournalError(f"{path}: not a flight journal ({error})") from None
    if found is None and not readonly:
        connection.execute("INSERT INTO meta VALUES ('format', ?)", (FORMAT,))
        connection.commit()
    elif found is None or found[0] != FORMAT:
        connection.close()
        raise JournalError(f"{path}: a journal of another format ({found[0] if found else 'none'}; this aeroexec "
                           f"reads {FORMAT})")
    return connection


def hold_lock(path: Path) -> int:
    """Hold the journal's lock file for this process's life: a second aeroexec cannot resume a run still flying
    (the lock goes with the process, however it ends)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(f"{path}.lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise JournalError(f"{path.parent}: the run is still flying (another aeroexec writes its journal)") from None
    return fd


def release_lock(fd: int, path: Path) -> None:
    """Let the journal go (its lock file removed: a run that ended holds nothing)."""
    with contextlib.suppress(OSError):
        os.unlink(f"{path}.lock")
    with contextlib.suppress(OSError):
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def is_flying(path: str | Path) -> bool:
    """Whether another process writes the journal at ``path`` now."""
    lock = f"{journal_path(path)}.lock"
    if not os.path.exists(lock):
        return False
    fd = os.open(lock, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)
    return False


__all__ = ["FORMAT", "NAME", "SCHEMA", "JournalError", "connect", "hold_lock", "is_flying", "journal_path",
           "release_lock"]
