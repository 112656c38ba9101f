"""What a journal belongs to, checked before a resume writes anything: the run (an identity made when it started,
in the journal's ``meta`` ``run`` and the event log's first line), its output folder (``meta`` ``folder``), and the
content of the files that shaped its flight (``meta`` ``files``: the mission, the world, the catalog, the rules and
safety rules files, the vehicle profile, each with its SHA-256), and times a clock can go on from.

A resume is refused, naming what differs, when the journal was copied from another run's folder, when a file that
shaped the flight changed since (a waypoint edited in a tree, a rule changed: the journal's progress is that of
another mission), or when the journal's times are not ones a run could have reached (:data:`LATEST`).
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

from aeroexec.flight.journal.schema import JournalError

from aeroexec.cache import sha256

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: Latest engine time (s) a resumed run may go on from: about 116 days of flight; later is a damaged journal.
LATEST = 1e7
FIRST_LINE = 1 << 20  # bytes of the event log's first line read, at most
INCLUDE = r"""<include\s[^>]*?path\s*=\s*["']([^"']+)["']"""  # compiled on first use (an XML mission's)
TAIL = 1 << 16  # bytes of the event log's end read for its last time


@dataclass(frozen=True)
class FlightFile:
    """A file that shaped a flight: its ``role`` (mission, world, catalog, rules, safety rules), path, SHA-256
    (None: it could not be read)."""

    role: str
    path: str
    sha256: str | None

    def as_meta(self) -> dict[str, Any]:
        return {"role": self.role, "path": self.path, "sha256": self.sha256}


def new_run_id() -> str:
    """A run's identity (kept by every resume of it); never a number, so the journal's meta reads it as text."""
    random = bytearray(os.urandom(16))  # uuid.uuid4().hex, without importing uuid and platform (~2 ms of a start)
    random[6] = (random[6] & 0x0F) | 0x40  # version 4
    random[8] = (random[8] & 0x3F) | 0x80  # RFC 4122's variant
    return f"run-{random.hex()}"


def digest(path: str | Path) -> str | None:
    """The SHA-256 of ``path``'s content (None when it cannot be read)."""
    sha = sha256()  # hashlib's digest, without its OpenSSL (aeroexec.cache)
    try:
        with open(path, "rb") as file:
            for block in iter(lambda: file.read(1 << 16), b""):
                sha.update(block)
    except OSError:
        return None
    return sha.hexdigest()


def flight_files(mission: str | Path, world: str | Path | None, catalog: str | Path | None,
                 rules: tuple[str, ...] | list[str], safety_rules: tuple[str, ...] | list[str],
                 vehicle: str | Path | None = None) -> list[FlightFile]:
    """The files that shape a flight, with their digests now (a tree's included files too; the vehicle profile:
    its endurance, speeds and ceiling bound the route, the simulator and the safety rules)."""
    named = [("mission", mission), *(("included", path) for path in included(Path(mission))), ("world", world),
             ("catalog", catalog), *(("rules", path) for path in rules),
             *(("safety rules", path) for path in safety_rules), ("vehicle profile", vehicle)]
    return [FlightFile(role, str(Path(path).resolve()), digest(path)) for role, path in named if path]


def included(mission: Path) -> list[Path]:
    """The files a BehaviorTree.CPP XML mission includes (``<include path="..."/>``, relative to the including
    file), and theirs, in the order they are first named."""
    found: list[Path] = []
    todo = [mission] if mission.suffix.lower() == ".xml" else []
    seen = {mission.resolve()}
    while todo:
        including = todo.pop(0)
        try:
            text = including.read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
        for name in re.findall(INCLUDE, text):
            path = (including.parent / name).resolve()
            if path not in seen:
                seen.add(path)
                found.append(path)
                todo.append(path)
    return found


def check_files(journal: Path, journaled: Any, now: list[FlightFile]) -> None:
    """JournalError naming the first file whose content differs from the journaled one's (``journaled``: the
    journal's ``files``; ``now``: the resumed flight's)."""
    if not isinstance(journaled, list):
        raise JournalError(f"{journal}: the journal is damaged: it does not say which files shaped its flight "
                           f"(meta 'files')")
    kept: dict[str, list[dict[str, Any]]] = {}
    for entry in journaled:
        if not isinstance(entry, dict) or not isinstance(entry.get("role"), str):
            raise JournalError(f"{journal}: the journal is damaged: a file of its flight without its role "
                               f"(meta 'files': {entry!r})")
        kept.setdefault(entry["role"], []).append(entry)
    roles = {file.role for file in now} | set(kept)
    for role in sorted(roles):
        then = kept.get(role, [])
        current = [file for file in now if file.role == role]
        if len(then) != len(current):
            raise JournalError(f"{journal}: the interrupted run was flown with {len(then)} {role} file(s), this "
                               f"resume with {len(current)}: resume it with the files it flew with")
        for old, new in zip(then, current, strict=True):
            if new.sha256 is None:
                raise JournalError(f"{new.path}: the {role} file of the interrupted run cannot be read: resume it "
                                   f"with the files it flew with")
            if old.get("sha256") != new.sha256:
                moved = f" (journaled as {old.get('path')})" if old.get("path") != new.path else ""
                raise JournalError(f"{new.path}: the {role} file changed since the interrupted run flew it{moved}: "
                                   f"its content is not the journaled one (SHA-256 {new.sha256[:12]}, journaled "
                                   f"{str(old.get('sha256'))[:12]}); a resume flies the mission as it was: put the "
                                   f"file back as it was, or fly the new one from its start (aeroexec run)")


def changed_files(folder: str | Path) -> list[str]:
    """The files that shaped the run in ``folder`` whose content now differs from the journaled one's, in words
    (an empty list: a resume now flies the mission the journal holds; a campaign's invariant after a resume)."""
    from aeroexec.flight.journal.reader import Journal  # here: only a resume reads a journal

    with Journal(folder) as journal:
        journaled = journal.meta().get("files")
    if not isinstance(journaled, list):
        return [f"{folder}: the journal does not say which files shaped its flight"]
    found = []
    for entry in journaled:
        now = digest(entry.get("path", "")) if isinstance(entry, dict) else None
        if not isinstance(entry, dict) or now != entry.get("sha256"):
            what = entry.get("role", "?") if isinstance(entry, dict) else "?"
            where = entry.get("path") if isinstance(entry, dict) else entry
            found.append(f"{where}: the {what} file {'cannot be read' if now is None else 'changed'}")
    return found


def first_record(log: Path) -> dict[str, Any] | None:
    """The event log's first line (``log_started``), or None when there is none to read."""
    try:
        with open(log, "rb") as file:
            line = file.readline(FIRST_LINE)
        record = json.loads(line)
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def check_belongs(journal: Path, meta: dict[str, Any], folder: Path, log: Path) -> None:
    """JournalError when the journal is not this folder's run's: written in another folder (copied from there;
    a whole run folder moved, its event log's run the journal's, is the same run), or beside the event log of
    another run."""
    run = meta.get("run")
    logged = meta.get("log") if isinstance(meta.get("log"), dict) else {}
    flown_in = meta.get("folder") or logged.get("output")
    if not isinstance(run, str) or not isinstance(flown_in, str):
        missing = "run" if not isinstance(run, str) else "folder"
        raise JournalError(f"{journal}: the journal does not say which run it is (meta '{missing}' missing): it "
                           f"cannot be resumed")
    started = first_record(log)
    log_run = started.get("run") if started is not None else None
    if log_run is not None and log_run != run:
        raise JournalError(f"{journal}: the journal is of run {run} (flown in {flown_in}), the event log {log} of "
                           f"run {log_run}: the journal was copied from another run's folder; resume that run in "
                           f"its own folder")
    if Path(flown_in).resolve() != folder.resolve() and log_run != run:
        raise JournalError(f"{journal}: the journal is of run {run}, flown in {flown_in}, not in this folder "
                           f"({folder.resolve()}): it was copied from another run's folder; resume that run in its "
                           f"own folder")


def check_time(file: Path, time: Any, what: str, damaged: str = "the journal") -> float:
    """``time`` (engine s) as a time a run can go on from; JournalError naming ``file`` (``damaged``: the journal,
    or the event log) when it is not."""
    if isinstance(time, bool) or not isinstance(time, int | float) or not math.isfinite(time) \
            or not 0.0 <= time <= LATEST:
        raise JournalError(f"{file}: {damaged} is damaged: {what} is t={time!r} s, not a time a run reaches (0 to "
                           f"{LATEST:g} s): the run cannot be resumed")
    return float(time)


def last_logged_time(log: Path) -> float | None:
    """The time of the event log's last whole record (a killed run's log holds its last period, which its journal
    may not yet), or None when it has none; JournalError naming the log when that time is not a plausible one."""
    try:
        with open(log, "rb") as file:
            size = file.seek(0, 2)
            file.seek(max(0, size - TAIL))
            tail = file.read()
    except OSError:
        return None
    for line in reversed(tail.split(b"\n")):
        try:
            record = json.loads(line)
        except ValueError:
            continue  # a torn last line, or the first one cut by the tail's start
        if isinstance(record, dict) and "time" in record:
            return check_time(log, record["time"], "its last record", "the event log")
    return None


__all__ = ["LATEST", "FlightFile", "changed_files", "check_belongs", "check_files", "check_time", "digest",
           "first_record", "flight_files", "included", "last_logged_time", "new_run_id"]
