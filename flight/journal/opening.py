"""A flight's journal opened: a new one, or an interrupted run's going on (:func:`open_journal`), apart from what a
resume reads (:mod:`.resumption`, :mod:`.resume_point`, :mod:`.rejoin`): a run that is not resumed imports none of
them (~4 ms of every run's start, ``bench/startup.py``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from aeroexec.engine.missions.replay import MissionRecorder
from aeroexec.flight.flight_log import plain
from aeroexec.flight.journal.writer import JournalWriter

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.flight.journal.identity import FlightFile
    from aeroexec.flight.spec import FlightSpec


def open_journal(engine: Any, spec: FlightSpec, folder: Path, log: dict[str, Any], *, python: bool,
                 resumption: Any = None, files: list[FlightFile] = ()) -> JournalWriter:
    """The journal of a flight in ``folder``: a new one (``log``: what the event log's first line says, with the
    run's identity ``run``; ``files``: those that shaped the flight, with their digests), or the interrupted run's
    going on (``resumption``, a :class:`.resumption.Resumption`); a Python mission's calls go through a recorder
    (journaled, replayed on a resume). JournalError when it cannot be written."""
    asked = plain(dataclasses.asdict(spec))
    for key in ("world", "catalog", "log", "answers", "vehicle"):  # files as paths a resume finds from any folder
        if asked.get(key):
            asked[key] = str(Path(asked[key]).resolve())
    for key in ("rules", "safety_rules"):
        asked[key] = [str(Path(p).resolve()) for p in asked.get(key) or ()]
    if isinstance(asked.get("fleet"), dict):
        asked["fleet"].pop("token", None)  # the token stays in the fleet's own file
        if asked["fleet"].get("credentials"):
            asked["fleet"]["credentials"] = str(Path(asked["fleet"]["credentials"]).resolve())
    journal = JournalWriter(engine, folder, meta={"mission": str(Path(spec.mission).resolve()),
                                                  "kind": "python" if python else "tree", "spec": asked, "log": log,
                                                  "run": log.get("run"), "folder": str(Path(folder).resolve()),
                                                  "files": [file.as_meta() for file in files]},
                            supersede_from=resumption.supersede_from if resumption is not None else None)
    if python:
        engine.bridge.recorder = (resumption.recorder(engine, journal) if resumption is not None
                                  else MissionRecorder(journal, engine.now))
    return journal


__all__ = ["open_journal"]
