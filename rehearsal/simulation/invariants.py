"""The invariants every case of the campaign is judged by, each with its name (a violation says which one held
not): what a user of ``aeroexec run`` is promised whatever the mission, the operator and the faults did.

- ``landed_and_disarmed``: the drone ends on the ground and disarmed (unless the link was lost at the end, or the
  vehicle crashed into something, which the run must then call failed);
- ``exit_status_agrees``: the exit status is the one the ``run_ended`` line states (and a real process's last
  line says);
- ``event_log_whole``: every line of ``events.jsonl`` parses, and each part that ended closes with a
  ``log_closed`` that counts its lines;
- ``journal_agrees_with_log``: every event the journal and the event log both hold is the same in each, in the
  same order;
- ``goals_at_most_once``: over a run and its resumption, each leaf of a tree without loops reaches its goal at
  most once;
- ``flies_the_journaled_mission``: a resumed run flies no point but the mission's (and its live edits');
- ``no_internal_error``: nothing raised out of the flight, nothing logged "please report it" or a traceback;
- ``step_bound``: no engine step takes more than :data:`STEP_BOUND` CPU seconds of the loop's thread;
- ``contingency_kept``: a ``return`` contingency ends with the drone home, a ``hold`` with it landed where it held;
- ``memory_bound``: the process stays under :data:`MEMORY_BOUND` MB.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from aeroexec.rehearsal.simulation.flights import Flown

STEP_BOUND = 0.1  # CPU s of the loop's thread for one engine step
MEMORY_BOUND = 1500.0  # MB: the peak resident memory of the process flying the cases
HOME_RADIUS = 3.0  # m: a return contingency brought the drone home
HOLD_RADIUS = 3.0  # m: a hold contingency landed the drone where it held
GROUND = 0.3  # m: on the ground
LOG_KINDS = ("log_started", "log_resumed", "log_closed")
MOTION = ("position(", "speed(", "orientation(", "velocity(")


@dataclass(frozen=True)
class Violation:
    """An invariant that did not hold for a case, and why."""

    invariant: str
    detail: str

    def __str__(self) -> str:
        return f"{self.invariant}: {self.detail}"


def _log_lines(flown: Flown) -> tuple[list[dict[str, Any]], list[str]]:
    """The event log's records and, for each line that does not parse, why."""
    path = flown.folder / "events.jsonl"
    records, bad = [], []
    if not path.is_file():
        return records, bad
    for number, line in enumerate(path.read_bytes().split(b"\n"), 1):
        if not line:
            continue
        try:
            record = json.loads(line)
            if not isinstance(record, dict):
                raise ValueError("not an object")
            records.append(record)
        except ValueError as error:
            bad.append(f"line {number}: {error}: {line[:80]!r}")
    return records, bad


def _segments(records: list[dict[str, Any]]) -> list[list[dict[str, Any]]]:
    parts: list[list[dict[str, Any]]] = []
    for record in records:
        if record.get("kind") in ("log_started", "log_resumed") or not parts:
            parts.append([])
        parts[-1].append(record)
    return parts


def _flew(flown: Flown) -> bool:
    return any(part.refused is None and part.error is None for part in flown.parts)


def landed_and_disarmed(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    last = flown.parts[-1] if flown.parts else None
    if last is None or last.refused is not None or last.crashed or last.error is not None:
        return []
    if not last.link_ok or last.crashed_drone or not last.state_known:
        return []
    on_ground = last.landed_state == "on_ground" if last.landed_state else last.altitude <= GROUND  # or a deck
    if last.armed or not on_ground:
        return [f"the drone ended {'armed' if last.armed else 'disarmed'} at {last.altitude:.2f} m "
                f"({last.outcome.status.word if last.outcome else 'no outcome'})"]
    return []


def exit_status_agrees(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    from aeroexec.flight.run_status import EXIT_STATUS, RunStatus, exit_status

    last = flown.parts[-1] if flown.parts else None
    if last is None or last.outcome is None:
        return []
    outcome = last.outcome
    found = []
    ended = [r for r in _segments(records)[-1] if r.get("kind") == "run_ended"] if records else []
    if ended:
        word = ended[-1].get("detail")
        stated = (ended[-1].get("data") or {}).get("exit_status")
        if word != outcome.status.word:
            found.append(f"run_ended says {word!r}, the run ended {outcome.status.word!r}")
        # an output lost (the event log cut short, photos a full disk did not take) makes a run that neither failed
        # nor was aborted exit 6, run_ended says so
        lost = outcome.log_incomplete is not None or any(r.get("kind") == "photo_not_saved" for r in records)
        expected = exit_status(RunStatus(word), lost) if word in EXIT_STATUS else None
        if expected is not None and stated != expected:
            found.append(f"run_ended says {word!r} with exit status {stated}, which is {expected}")
        if expected is not None and outcome.exit_status != expected:
            found.append(f"exit status {outcome.exit_status} for a run_ended {word!r}")
    elif outcome.log_incomplete is None:
        found.append("the event log has no run_ended line though it is whole")
    if flown.exit_status is not None and flown.exit_status != outcome.exit_status:
        found.append(f"the process exited {flown.exit_status}, its run ended {outcome.status.word!r} "
                     f"(exit status {outcome.exit_status})")
    if flown.exit_status is not None and "exit status" in flown.last_line and \
            f"exit status {flown.exit_status}" not in flown.last_line:
        found.append(f"the last line says {flown.last_line!r}, the process exited {flown.exit_status}")
    return found


def event_log_whole(flown: Flown, records: list[dict[str, Any]], bad: list[str]) -> list[str]:
    found = list(bad[:3])
    if not _flew(flown):
        return found
    segments = _segments(records)
    closing = [p for p in flown.parts if p.refused is None and p.error is None]
    for number, (segment, part) in enumerate(zip(segments, closing, strict=False), 1):
        closed = [i for i, r in enumerate(segment) if r.get("kind") == "log_closed"]
        whole = part.outcome is not None and part.outcome.log_incomplete is None
        if part.crashed:
            if closed:
                found.append(f"part {number} was killed, yet its log says log_closed")
            continue
        if whole and not closed:
            found.append(f"part {number} ended whole without a log_closed line")
        if closed:
            counted = segment[closed[-1]].get("lines")
            if closed[-1] != len(segment) - 1:
                found.append(f"part {number}: log_closed is not its last line")
            if counted != len(segment):
                found.append(f"part {number}: log_closed counts {counted} lines, the part has {len(segment)}")
        if not whole and closed:
            found.append(f"part {number}: the log is incomplete ({part.outcome.log_incomplete}) yet says log_closed")
    return found


def _key(record: dict[str, Any]) -> tuple:
    return (round(float(record.get("time", 0.0)), 3), record.get("kind"), record.get("behavior", ""),
            str(record.get("detail", "")), record.get("belief"))


def _compared(record: dict[str, Any]) -> bool:
    """A record both the journal and the event log hold: not a part's first or last line, a state sample or a
    drone's motion (each keeps those its own way)."""
    if record.get("kind") in LOG_KINDS or record.get("kind") == "state":
        return False
    return not str(record.get("belief") or "").startswith(MOTION)


def journal_agrees_with_log(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    from aeroexec.flight.journal import Journal, is_journal

    if not _flew(flown) or not is_journal(flown.folder):
        return []
    if any(f.kind == "foreign_journal" for f in flown.case.faults) and flown.parts[-1].refused:
        return []  # the folder's journal is another run's, copied over this one's, and its resume was refused
    with Journal(flown.folder) as journal:
        held = journal.records()
    found = []
    log_parts, journal_parts = _segments(records), _segments(held)
    incomplete = any(p.outcome is not None and p.outcome.log_incomplete for p in flown.parts)
    for number, (ours, theirs) in enumerate(zip(log_parts, journal_parts, strict=False), 1):
        logged = [_key(r) for r in ours if _compared(r)]
        journaled = [_key(r) for r in theirs if _compared(r)]
        places: dict[tuple, list[int]] = {}
        for i, key in enumerate(logged):
            places.setdefault(key, []).append(i)
        at, missing = 0, None
        cut_short = incomplete or (number <= len(flown.parts) and flown.parts[number - 1].crashed)
        for key in journaled:
            later = [i for i in places.get(key, ()) if i >= at]
            if later and missing is None:
                at = later[0] + 1
            elif later:  # the log holds a record after one it lacks: they disagree, not a log cut short
                found.append(f"part {number}: the journal holds {missing} which the event log has not")
                break
            elif missing is None:
                missing = key
        if missing is not None and not cut_short and not found:
            found.append(f"part {number}: the journal holds {missing} which the event log has not")
    return found


def _goals(records: list[dict[str, Any]]) -> dict[int, int]:
    counts: dict[int, int] = {}
    leaves: dict[int, bool] = {}
    for record in records:
        if record.get("kind") != "node_status":
            continue
        data = record.get("data") or record
        uid = data.get("uid")
        kind = str(data.get("type", ""))
        leaves[uid] = kind.isupper()
        if data.get("new") == "SUCCESS" and leaves[uid]:
            counts[uid] = counts.get(uid, 0) + 1
    return counts


def goals_at_most_once(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    case = flown.case
    if case.mission.kind != "tree" or case.mission.repeats or len(flown.parts) < 2 or any(
            a.command in ("insert", "replace", "delete", "load", "skip", "jump") for a in case.actions):
        return []
    again = {uid: n for uid, n in _goals(records).items() if n > 1}
    return [f"leaf {uid} of the tree reached its goal {n} times over the run and its resumption"
            for uid, n in sorted(again.items())][:3]


def flies_the_journaled_mission(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    if len(flown.parts) < 2 or flown.case.mission.kind == "plan":
        return []
    segments = _segments(records)
    found = []
    for record in (r for segment in segments[1:] for r in segment):
        if record.get("kind") == "activated" and record.get("behavior") == "GO_TO_POINT" and \
                (record.get("data") or {}).get("source") == "mission":
            where = (record.get("arguments") or {}).get("COORDINATES")
            if isinstance(where, list) and len(where) == 3 and all(isinstance(v, int | float) for v in where):
                point = tuple(round(float(v), 1) for v in where)
                if not any(math.dist(point, p) < 0.15 for p in flown.allowed_points):
                    found.append(f"the resumed run flew to {point}, a point of no mission it was given")
    return found[:1]


def no_internal_error(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    found = [part.error for part in flown.parts if part.error]
    found += flown.logged[:3]
    found += [f"ctl {command}: {message}" for part in flown.parts for command, _, message in part.answers
              if "please report it" in message or "Traceback" in message][:3]
    if flown.exit_status == 70:
        found.append(f"exit status 70: {flown.last_line}")
    return found


def step_bound(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    return [f"an engine step of part {n} at t={part.longest_at:.2f} s took {part.longest_step * 1000:.0f} ms of CPU "
            f"(bound {STEP_BOUND * 1000:.0f} ms)" for n, part in enumerate(flown.parts, 1)
            if part.longest_step > STEP_BOUND]


def contingency_kept(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    last = flown.parts[-1] if flown.parts else None
    if last is None or last.outcome is None or last.crashed_drone or len(flown.parts) > 1:
        return []
    segment = _segments(records)[-1] if records else []
    violated = [r for r in segment if r.get("kind") == "safety_violated"]
    if not violated or last.outcome.status.word in ("aborted",) or any(
            r.get("kind") in ("engine_time_limit", "operator_interrupt") for r in segment):
        return []
    first = violated[0].get("data") or {}
    if any((r.get("data") or {}).get("contingency") != first.get("contingency") for r in violated[1:]):
        return []  # another rule's contingency took over
    contingency = str(first.get("contingency", ""))
    x, y, _ = last.position
    if contingency.startswith("return") and math.hypot(x, y) > HOME_RADIUS:
        return [f"a return contingency ({first.get('rule')}) left the drone {math.hypot(x, y):.1f} m from home"]
    if contingency.startswith("hold"):
        states = [r for r in segment if r.get("kind") == "state" and r.get("time", 0) >= violated[0].get("time", 0)]
        if states:
            hx, hy = states[0]["position"][:2]
            if math.hypot(x - hx, y - hy) > HOLD_RADIUS:
                return [f"a hold contingency ({first.get('rule')}) began at ({hx:.1f}, {hy:.1f}); the drone "
                        f"landed {math.hypot(x - hx, y - hy):.1f} m away"]
    return []


def memory_bound(flown: Flown, records: list[dict[str, Any]]) -> list[str]:
    if flown.peak_memory > MEMORY_BOUND:
        return [f"the process reached {flown.peak_memory:.0f} MB (bound {MEMORY_BOUND:.0f} MB)"]
    return []


INVARIANTS = (landed_and_disarmed, exit_status_agrees, event_log_whole, journal_agrees_with_log,
              goals_at_most_once, flies_the_journaled_mission, no_internal_error, step_bound, contingency_kept,
              memory_bound)


def check(flown: Flown) -> list[Violation]:
    """Every invariant that did not hold for the case flown."""
    records, bad = _log_lines(flown)
    found: list[Violation] = []
    for invariant in INVARIANTS:
        try:
            details = invariant(flown, records, bad) if invariant is event_log_whole else invariant(flown, records)
        except Exception as error:  # noqa: BLE001 - a check that cannot read what the run left: said as such
            details = [f"could not be checked: {type(error).__name__}: {error}"]
        found += [Violation(invariant.__name__, detail) for detail in details]
    return found


__all__ = ["HOME_RADIUS", "INVARIANTS", "MEMORY_BOUND", "STEP_BOUND", "Violation", "check"]
