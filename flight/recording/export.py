"""A finished run's folder made an MCAP recording (``aeroexec export RUN_DIR --mcap FILE``).

A run's folder holds its event log (``events.jsonl``, else its journal); a fleet's folder (``aeroexec fleet``) holds
one folder per drone, each a run's, and ``fleet_status.json`` naming them in the fleet's order. A fleet makes one
file, the topics of each drone under its name and every drone's frame on ``/tf``, the drones' records merged by
time (they flew on one clock). The planned route comes from the mission file the run's journal names, when the
file is still there.
"""

from __future__ import annotations

import heapq
import json
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.flight.flight_log import read_numbered_log
from aeroexec.flight.journal import NAME as JOURNAL
from aeroexec.flight.journal import Journal, JournalError, is_journal, read_records
from aeroexec.flight.recording.mcap_file import McapFile
from aeroexec.flight.recording.recorder import Recorder, start_ns
from aeroexec.flight.recording.topics import Drone

logger = logging.getLogger(__name__)
LOG = "events.jsonl"
FLEET_STATUS = "fleet_status.json"


class RecordingError(ValueError):
    """A run that cannot be recorded: the message names the file (and line) and what is wrong."""


@dataclass
class DroneLog:
    """One drone's records (with their lines; 0 when read from a journal) and where they come from."""

    name: str
    path: Path
    records: list[tuple[int, dict[str, Any]]]
    meta: dict[str, Any] = field(default_factory=dict)


@dataclass
class Exported:
    """What was written: messages per topic, the drones, and what could not be recorded (the route's absence)."""

    path: Path
    counts: dict[str, int]
    drones: list[str]
    notes: list[str] = field(default_factory=list)


def run_folders(folder: str | Path) -> list[Path]:
    """The run folders (or logs) a run's output folder holds: itself, or a fleet's drones' folders."""
    folder = Path(folder)
    if folder.is_file():
        return [folder]
    if not folder.is_dir():
        raise RecordingError(f"{folder}: no such folder (a run's output folder is expected)")
    if (folder / LOG).is_file() or is_journal(folder):
        return [folder]
    names: list[str] = []
    status = folder / FLEET_STATUS
    if status.is_file():
        try:
            names = [str(n) for n in json.loads(status.read_text(encoding="utf-8")).get("drones", {})]
        except (OSError, ValueError, AttributeError) as error:
            raise RecordingError(f"{status}: not a fleet's status ({error})") from None
    else:
        names = sorted(p.name for p in folder.iterdir() if p.is_dir() and (p / LOG).is_file())
    found = [folder / name for name in names if (folder / name / LOG).is_file() or is_journal(folder / name)]
    if not found:
        raise RecordingError(f"{folder}: not a run's output folder (no {LOG} or {JOURNAL} in it, nor a fleet's drone "
                             f"folders)")
    return found


def read_drone(path: Path, fleet: bool) -> DroneLog:
    """A drone's records from its run folder (its event log, else its journal) or a log file."""
    log = path / LOG if path.is_dir() else path
    try:
        if log.is_file() and not is_journal(log):
            records = read_numbered_log(log)
        else:
            log = path / JOURNAL if path.is_dir() else path
            records = [(0, r) for r in read_records(log)]
    except OSError as error:
        raise RecordingError(f"{log}: cannot read the event log: {error.strerror or error}") from None
    except ValueError as error:  # a line that is not JSON (file:line), not UTF-8, a journal that is not one
        message = str(error)
        raise RecordingError(message if str(log) in message else f"{log}: {message}") from None
    if not records:
        raise RecordingError(f"{log}: the event log is empty")
    line, first = records[0]
    if not isinstance(first, dict) or first.get("kind") not in ("log_started", "log_resumed"):
        raise RecordingError(f"{log}:{line or 1}: not an aeroexec event log (its first record is not log_started)")
    for line, record in records:
        if not isinstance(record, dict):
            raise RecordingError(f"{log}:{line}: not a JSON object")
        if isinstance(record.get("time"), bool) or not isinstance(record.get("time"), int | float):
            raise RecordingError(f"{log}:{line}: a record without its time (engine seconds)")
    default = path.name if fleet else "drone"
    name = str(first.get("drone_name") or default)
    return DroneLog(name, log, records, first)


def _home(meta: dict[str, Any]) -> tuple[float, float, float] | None:
    home = meta.get("home")
    if isinstance(home, list) and len(home) == 3 and all(isinstance(v, int | float) for v in home):
        return (float(home[0]), float(home[1]), float(home[2]))
    return None


def standing(records: Any) -> tuple[float, float]:
    """Where the drone stands at first (x, y): its first state sample's position, else home."""
    for record in records:
        position = record.get("position") if record.get("kind") == "state" else None
        if isinstance(position, list) and len(position) == 3:
            if all(isinstance(v, int | float) and not isinstance(v, bool) for v in position):
                return float(position[0]), float(position[1])
            return 0.0, 0.0
    return 0.0, 0.0


def planned_route(folder: Path, start: tuple[float, float]) -> tuple[list[tuple[float, float, float]] | None, str]:
    """The literal destinations of the mission the run's journal names, flown from ``start`` (ENU x, y); None and
    why not when there is no journal or mission file to read it from."""
    if not folder.is_dir() or not is_journal(folder):
        return None, f"{folder}: no journal names the mission: no planned route"
    try:
        with Journal(folder) as journal:
            meta = journal.meta()
    except (JournalError, OSError, ValueError) as error:
        return None, f"{folder / JOURNAL}: {error}: no planned route"
    mission = meta.get("mission")
    if not isinstance(mission, str) or not Path(mission).is_file():
        return None, f"{mission}: the mission file is not there: no planned route"
    return route_of(Path(mission), start), ""


def route_of(mission: Path, start: tuple[float, float]) -> list[tuple[float, float, float]] | None:
    """The literal destinations of the mission file ``mission`` (a tree of any format, or Python) from ``start``."""
    from dataclasses import replace

    from aeroexec.drones.vehicle import VehicleModel
    from aeroexec.engine.safety.static import route
    from aeroexec.trees.formats import format_of

    from aeroexec.limits import InputError, read_text

    fmt = format_of(mission)
    try:
        if fmt is not None and not fmt.tree:  # a program: its requests in the order written
            document: Any = read_text(mission, what="the mission")
        else:
            from aeroexec.trees import load_mission_tree

            document = load_mission_tree(mission)
        model = replace(VehicleModel(), home=(start[0], start[1], 0.0))
        return [model.home, *(w.point for w in route(document, str(mission), model))]
    except InputError as error:
        logger.warning("no planned route: %s", error.message)
    except Exception as error:  # the mission file changed since the flight: the recording goes on without a route
        logger.warning("no planned route from %s: %s", mission, error)
    return None


def export_mcap(run: str | Path, target: str | Path) -> Exported:
    """Write the recording of the run in ``run`` (a run's or a fleet's output folder, or an event log) to the MCAP
    file ``target``; :class:`RecordingError` naming the file and line when the run cannot be read."""
    folders = run_folders(run)
    fleet = len(folders) > 1 or Path(run) != folders[0]
    drones = [read_drone(folder, fleet) for folder in folders]
    if len({d.name for d in drones}) < len(drones):
        raise RecordingError(f"{run}: two drones share a name: {', '.join(d.name for d in drones)}")
    start = start_ns(drones[0].meta)
    frames = {d.name: Drone(d.name, _home(d.meta), start) for d in drones}
    recorder = Recorder([McapFile(target)])
    exported = Exported(Path(target), {}, [d.name for d in drones])
    try:
        first = drones[0].meta
        recorder.metadata("aeroexec", {"mission": first.get("mission", ""), "clock": first.get("clock", ""),
                                       "drones": ",".join(frames), "fleet": first.get("fleet", ""),
                                       "start_ns": start})
        for drone in drones:
            recorder.declare(frames[drone.name])
            if fleet:
                recorder.metadata(f"aeroexec.{drone.name}", {"mission": drone.meta.get("mission", ""),
                                                             "log": str(drone.path)})
        for folder, drone in zip(folders, drones, strict=True):
            points, why = planned_route(folder, standing(r for _, r in drone.records))
            if points is None:
                exported.notes.append(why)
            else:
                at = float(drone.records[0][1].get("time", 0.0))
                drone.records.insert(1, (0, {"time": at, "kind": "route", "points": [list(p) for p in points]}))
        merged = heapq.merge(*([(float(r.get("time", 0.0)), i, line, r) for line, r in d.records]
                               for i, d in enumerate(drones)), key=lambda item: item[0])
        for _, i, line, record in merged:
            drone = drones[i]
            try:
                recorder.record(frames[drone.name], record)
            except (KeyError, TypeError, ValueError, IndexError) as error:
                where = f"{drone.path}:{line}" if line else str(drone.path)
                raise RecordingError(f"{where}: a {record.get('kind')!s} record that cannot be recorded "
                                     f"({type(error).__name__}: {error})") from None
    except BaseException:
        recorder.close(keep=False)
        raise
    recorder.close()
    exported.counts = dict(recorder.counts)
    return exported


__all__ = ["Exported", "RecordingError", "export_mcap", "route_of", "run_folders", "standing"]
