"""The journal's database as its writer holds it: the run's lock, batches of rows each committed in one
transaction on the caller's thread (the engine's loop), and the WAL checkpointed by a thread of its own.

A commit in WAL mode with ``synchronous=NORMAL`` appends the transaction's pages to the WAL file and waits for no
disk: as ``events.jsonl``'s lines, it reaches the operating system at once (a ``kill -9`` of the process loses
nothing committed), and the disk later (a power cut may lose the last commits, never the database's consistency).
The one write that waits for the disk, the checkpoint (the WAL made durable and copied into the database), is
not the loop's: SQLite's automatic checkpoint is off and the ``aeroexec-journal`` thread checkpoints, on a
connection of its own and without holding up the commits, every ``CHECKPOINT_COMMITS`` commits (the WAL stays
small) or ``CHECKPOINT_PERIOD`` s of wall time after a commit (what a power cut can take: the last seconds).
"""

from __future__ import annotations

import contextlib
import logging
import sqlite3
import threading
from pathlib import Path

from aeroexec.flight.journal.schema import connect, hold_lock, release_lock

logger = logging.getLogger(__name__)

CHECKPOINT_PERIOD = 5.0  # s of wall time a commit waits at most for its checkpoint
CHECKPOINT_COMMITS = 200  # commits that make a checkpoint at once (a WAL of about a MB)
#: One row: its statement (one of the writer's constants, compared by identity) and its parameters.
Row = tuple[str, tuple]


class JournalStore:
    """The journal at ``path``, held by this process (a second aeroexec cannot write it) until :meth:`close`."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.incomplete: str | None = None  # why the journal stopped short (the write's error), None while whole
        self._lock_file = hold_lock(path)
        try:
            self.db = connect(path)
            self.db.execute("PRAGMA wal_autocheckpoint=0")  # checkpoints are the thread's, not the loop's
        except BaseException:
            release_lock(self._lock_file, path)
            raise
        self._lock = threading.Lock()  # one transaction at a time (the loop's, or a closing thread's)
        self._closing = threading.Event()
        self._commits = 0  # commits since the last checkpoint began
        self._due = threading.Event()  # CHECKPOINT_COMMITS commits since
        self._checkpointer = threading.Thread(target=self._checkpoint, name="aeroexec-journal", daemon=True)
        self._checkpointer.start()

    def write(self, rows: list[Row]) -> None:
        """Commit ``rows`` in one transaction, each run of rows of one statement in one call. A journal that
        cannot be written (a full disk) stops: :attr:`incomplete` says why, and nothing more is written."""
        with self._lock:
            if self.incomplete is not None or self._closing.is_set():
                return
            try:
                with self.db:
                    self._write(rows)
                self._commits += 1
                if self._commits == CHECKPOINT_COMMITS:
                    self._due.set()
            except sqlite3.Error as error:
                self.incomplete = str(error)
                logger.error("the journal %s cannot be written (%s): it stops here; the flight goes on", self.path,
                             error)

    def _write(self, rows: list[Row]) -> None:
        many, statement, params = self.db.executemany, rows[0][0], []
        for row in rows:
            if row[0] is not statement:
                many(statement, params)
                statement, params = row[0], []
            params.append(row[1])
        many(statement, params)

    def _checkpoint(self) -> None:
        try:
            db = sqlite3.connect(self.path, timeout=0.0, check_same_thread=False)
        except sqlite3.Error as error:
            logger.warning("the journal %s is not checkpointed (%s): its WAL grows until the run ends", self.path,
                           error)
            return
        with contextlib.closing(db):
            while True:
                self._due.wait(CHECKPOINT_PERIOD)
                if self._closing.is_set():
                    return
                self._due.clear()
                if not self._commits:
                    continue
                self._commits = 0
                try:
                    for _ in range(5):  # again while commits came during it: a WAL checkpointed whole starts over
                        _, frames, done = db.execute("PRAGMA wal_checkpoint(PASSIVE)").fetchone()
                        if done >= frames:
                            break
                except sqlite3.Error as error:  # busy, or a full disk: the next one goes on
                    logger.debug("the journal %s: checkpoint put off (%s)", self.path, error)

    def close(self) -> None:
        """Stop the checkpoints, close the database (its last checkpoint, on this thread) and let the run go."""
        self._closing.set()
        self._due.set()
        self._checkpointer.join(timeout=30.0)
        with self._lock, contextlib.suppress(sqlite3.Error):
            self.db.close()
        release_lock(self._lock_file, self.path)


__all__ = ["CHECKPOINT_COMMITS", "CHECKPOINT_PERIOD", "JournalStore", "Row"]
