"""Whether a run's journal and its event log agree (:func:`disagreements`): the invariant a test, or a campaign of
simulated flights, checks after a run however it ended (completed, interrupted, killed and resumed). Both hold the
run's records, part by part (``log_started``, then a ``log_resumed`` line per resume; the journal's segments). They
agree when, in each part, the records both are to hold are the same records in the same order: every event and every
belief change, but the drone's own motion (``position``/``speed``/``orientation`` of ``self``: the journal keeps
state samples instead) and the state samples (each file samples on its own). Neither holds a fleet mate's shared
position (it is not the drone's state: both say it as a ``fleet_drone_heard`` event). A part that ended (the journal
says how) holds the same records in both; a part whose process was killed may hold more in the event log (its last
lines, written before the journal's next commit), never fewer, never others.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path
from typing import Any

from aeroexec.flight.journal.reader import Journal
from aeroexec.flight.journal.schema import JournalError

#: Records of the event log that are not the journal's to hold.
LOG_ONLY = frozenset({"log_started", "log_resumed", "log_closed", "state"})
MOTION = ("position(self,", "speed(self,", "orientation(self,")


def _held_by_both(record: dict[str, Any]) -> bool:
    kind = record.get("kind")
    if kind in LOG_ONLY:
        return False
    if kind in ("belief_added", "belief_removed"):
        belief = str(record.get("belief", "")).replace(" ", "")
        return not belief.startswith(MOTION)
    return True


def _log_parts(log: Path) -> tuple[list[list[dict[str, Any]]], list[str]]:
    """The event log's records, part by part, and what could not be read of it."""
    parts: list[list[dict[str, Any]]] = []
    problems: list[str] = []
    with open(log, encoding="utf-8", errors="replace") as file:
        for number, line in enumerate(file, 1):
            if not line.endswith("\n"):
                problems.append(f"{log}:{number}: a torn last line (the process was killed writing it)")
                continue
            try:
                record = json.loads(line)
            except ValueError as error:
                problems.append(f"{log}:{number}: not a record ({error})")
                continue
            if record.get("kind") in ("log_started", "log_resumed") or not parts:
                parts.append([])
            parts[-1].append(record)
    return parts, problems


def _key(record: dict[str, Any]) -> str:
    return json.dumps(record, sort_keys=True, separators=(",", ":"))


def _counts(records: list[dict[str, Any]]) -> str:
    counted = Counter(str(r.get("kind")) for r in records)
    return ", ".join(f"{n} {kind}" for kind, n in sorted(counted.items())) or "none"


def disagreements(folder: str | Path, log: str | Path | None = None) -> list[str]:
    """Where the journal of the run in ``folder`` and its event log (``log``, else ``folder/events.jsonl``)
    disagree, in words, one entry each (an empty list: they agree; see the module's docstring)."""
    folder = Path(folder)
    log = Path(log) if log is not None else folder / "events.jsonl"
    try:
        parts, problems = _log_parts(log)
    except OSError as error:
        return [f"{log}: the event log cannot be read ({error.strerror or error})"]
    try:
        with Journal(folder) as journal:
            segments = journal.segments()
            rows = journal.rows("SELECT segment, record FROM events ORDER BY seq")
            kept = [(r["segment"], journal.json(r["record"])) for r in rows]
    except JournalError as error:
        return [*problems, str(error)]
    found = list(problems)
    if len(parts) != len(segments):
        found.append(f"the event log has {len(parts)} part(s) (log_started, log_resumed), the journal "
                     f"{len(segments)} segment(s)")
    for n, (part, segment) in enumerate(zip(parts, segments, strict=False), 1):
        logged = [r for r in part if _held_by_both(r)]
        journaled = [r for of, r in kept if of == segment.segment and _held_by_both(r)]
        ended = segment.status is not None
        compared = logged if ended else logged[:len(journaled)]
        where = f"part {n} ({'ended ' + segment.status if ended else 'killed'})"
        if len(journaled) > len(logged) or (ended and len(journaled) != len(logged)):
            found.append(f"{where}: the event log holds {len(logged)} records ({_counts(logged)}), the journal "
                         f"{len(journaled)} ({_counts(journaled)})")
        for index, (one, other) in enumerate(zip(compared, journaled, strict=False)):
            if _key(one) != _key(other):
                found.append(f"{where}: record {index + 1} differs: the event log has {_key(one)}, the journal "
                             f"{_key(other)}")
                break
    return found


__all__ = ["disagreements"]
