"""A finished run for the console's replay: the records of its event log that the page needs to rebuild any moment."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from aeroexec.flight.journal import NAME, is_journal, read_records

KEPT = ("state", "belief_added", "belief_removed")  # besides the engine's events


class ReplayError(ValueError):
    """The run folder or log cannot be replayed."""


def find_log(path: str | Path) -> Path:
    """The record of a run: ``path`` itself (an event log, a journal), or in a run's output folder its
    ``events.jsonl``, else its ``journal.sqlite``."""
    path = Path(path)
    log = path / "events.jsonl" if path.is_dir() else path
    if not log.is_file() and path.is_dir() and is_journal(path):
        log = path / NAME
    if not log.is_file():
        raise ReplayError(f"{path}: no event log here (a run's output folder, its events.jsonl or its journal.sqlite "
                          f"is expected)")
    return log


def replay_of(path: str | Path) -> dict[str, Any]:
    """``{"mission", "end", "drones": {name: records}}`` of a run's event log (or journal), ready for the page."""
    log = find_log(path)
    try:
        records = read_records(log)
    except OSError as error:
        raise ReplayError(f"{log}: cannot read the event log: {error.strerror or error}") from None
    except ValueError as error:  # not JSON lines, not UTF-8
        raise ReplayError(str(error) if str(log) in str(error) else f"{log}: {error}") from None
    meta = next((r for r in records if r.get("kind") == "log_started"), {})
    kept = [r for r in records if r.get("kind") not in ("log_started", "log_resumed", "log_closed")]
    end = max((float(r.get("time", 0.0)) for r in kept), default=0.0)
    return {"mission": meta.get("mission", log.parent.name), "end": end, "world": meta.get("world"),
            "home": meta.get("home"), "bounds": meta.get("bounds"),  # the world a run flew in, as its log says
            "drone": meta.get("drone"),
            "drones": {str(meta.get("drone_name") or "drone"): kept}}
