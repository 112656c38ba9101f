"""Where an interrupted run is to go on from, read from its journal (:func:`resume_point`).

The mission's progress comes from the last segment that went live (a resume refused before it flew, a diverged
Python mission, changed nothing): up to where it stopped (its ``stop``: a safety reaction, ``ctl suspend``, an
abort, the time limit), or to its end when the process was killed. Then:

- a tree: its last kept state, and the goals reached after it was kept (a behavior's GOAL_ACHIEVED, or what makes
  it done at once: a photo taken, a message sent, an item dropped), which settle the leaves still running;
- a Python mission: its calls with their results, in order, and the call under way (made live again, unless its
  behavior's goal was reached meanwhile: then it is settled with that result);
- the beliefs held at the stop (the robot's own state excluded: the robot tells it again), each persistent one
  with what was left of its lifetime; the behaviors the mission had running in the background (recurrent ones,
  started by calls already done or by leaves already completed), to start again;
- the drone: where it was at the stop and whether it flew, and its last known state (a simulated drone is made
  again there: hovering after a crash, on the ground after a suspension with a full battery — the swap).

A run that completed, or whose mission failed by itself, has nothing to resume; a run still flying (its journal
locked) is not resumed either.
"""

from __future__ import annotations

import json
import math
import os
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.engine.catalog.engine_behaviors import LAND, TAKE_OFF
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.updaters import TELEMETRY_PREDICATES
from aeroexec.engine.missions.replay import RecordedCall
from aeroexec.engine.missions.values import canonical, encode
from aeroexec.flight.journal.identity import check_time
from aeroexec.flight.journal.reader import Journal
from aeroexec.flight.journal.schema import JournalError, is_flying

#: Events that say a behavior's work is done though its GOAL_ACHIEVED may not have been kept (event -> behavior:
#: a photo taken by TRIGGER_CAMERA, which goes on, says nothing of its end).
EFFECTS = {"photo_taken": "TAKE_PHOTO", "message_sent": "BROADCAST_MESSAGE", "item_dropped": "DROP_ITEM"}
ACHIEVED = Outcome.GOAL_ACHIEVED.value
UP = ("in_air", "taking_off")  # landed states of a drone flying as the mission meant it (landing is coming down)
SUSPENDED = "suspended"
FARTHEST = 1e6  # m from home: farther is a damaged journal's place, not a drone's


@dataclass
class ResumePoint:
    """What a resumed run restores (see the module's docstring)."""

    folder: Path
    meta: dict[str, Any]
    time: float  # engine time the resumed run starts at
    live_segment: int
    stop: dict[str, Any] | None  # where and why the mission stopped; None: the process was killed
    place: tuple[float, float, float]  # where the drone was when the mission stopped
    was_flying: bool
    drone: dict[str, Any] | None  # its last known state
    suspended: bool  # the run ended suspended (a battery swap): a simulated drone gets a full battery
    tree: str | None = None  # the tree's state (JSON)
    settled: dict[str, tuple[str, Any]] = field(default_factory=dict)  # behavior -> (why, result): goals reached
    calls: list[RecordedCall] = field(default_factory=list)
    pending: RecordedCall | None = None
    settled_call: RecordedCall | None = None  # the call under way whose goal was reached: replayed, kept again
    edits: list[dict[str, Any]] = field(default_factory=list)  # the changes made to the tree in flight, in order
    beliefs: list[tuple[str, float | None]] = field(default_factory=list)  # (belief, expires_at)
    active: list[dict[str, Any]] = field(default_factory=list)  # behavior, arguments, source, priority: at the stop

    @property
    def kind(self) -> str:
        return str(self.meta.get("kind", ""))

    def where(self) -> str:
        """Where the mission stopped, in words."""
        why = self.stop["reason"] if self.stop else "the process stopped without ending the run"
        at = self.stop["time"] if self.stop else self.time
        x, y, z = self.place
        return f"t={at:.1f} s ({why}); drone at ({x:.1f}, {y:.1f}, {z:.1f}){' flying' if self.was_flying else ''}"


def resume_point(folder: str | Path, period: float = 0.05) -> ResumePoint:
    """The resume point of the run in ``folder``; :class:`JournalError` (in words) when it cannot be resumed."""
    folder = Path(folder)
    if is_flying(folder):
        raise JournalError(f"{folder}: the run is still flying (another aeroexec writes its journal); "
                           f"stop it first (aeroexec ctl suspend --run {folder})")
    with Journal(folder) as journal:
        try:
            return _read(journal, folder, period)
        except (ValueError, KeyError, TypeError, IndexError, AttributeError, zlib.error) as error:
            raise JournalError(f"{journal.path}: the journal is damaged: {type(error).__name__}: {error}") from None


def _read(journal: Journal, folder: Path, period: float) -> ResumePoint:
    meta = journal.meta()
    segments = journal.segments()
    live = [s for s in segments if s.live_at is not None]
    if not live:
        raise JournalError(f"{folder}: the run's mission never started: nothing to resume (run it again)")
    segment = live[-1]
    if journal.rows("SELECT 1 FROM events WHERE segment = ? AND kind = 'mission_completed'", (segment.segment,)):
        raise JournalError(f"{folder}: the run completed: nothing is left to do")
    stopped = journal.progress(segment.segment, "stop")
    if stopped is None and segment.status is None:  # killed while the flight ended: its mission had failed already
        failed = journal.rows("SELECT detail FROM events WHERE segment = ? AND kind = 'mission_failed'",
                              (segment.segment,))
        if failed:
            raise JournalError(f"{folder}: the mission had ended failed by itself ({failed[0][0] or 'no reason'}) "
                               f"before the run was stopped while it landed: a run resumes from a stop (a crash, a "
                               f"suspension, an abort), not from a failure; run the mission again")
    if stopped is None and segment.status is not None:
        reasons = "; ".join(segment.reasons[:2]) or segment.status
        raise JournalError(f"{folder}: the mission ended {segment.status} by itself ({reasons}): a run resumes from "
                           f"a stop (a crash, a suspension, an abort), not from a failure; run the mission again")
    stop = stopped[2] if stopped is not None else None
    stop_seq = stopped[0] if stopped is not None else 1 << 62
    at_stop = (stop or {}).get("drone") or journal.last_state(segment.segment) or {}
    place = tuple(float(v) for v in at_stop.get("position", (0.0, 0.0, 0.0)))
    if len(place) != 3 or not all(math.isfinite(v) and abs(v) <= FARTHEST for v in place):
        raise JournalError(f"{journal.path}: the journal is damaged: the drone's place when the mission stopped, "
                           f"{list(place)}, is not one it can fly back to: the run cannot be resumed")
    last = check_time(journal.path, journal.last_time(), "its last time")
    point = ResumePoint(folder, meta, round(last + period, 3), segment.segment, stop,
                        place, at_stop.get("landed_state") in UP, journal.last_state(),  # type: ignore[arg-type]
                        suspended=segments[-1].status == SUSPENDED)
    done = _effects(journal, segment.segment, stop_seq)
    point.beliefs = _beliefs(journal, segment.segment, stop_seq)
    point.active = _active(journal, segment.segment, stop_seq)
    if point.kind == "tree":
        tree = journal.progress(segment.segment, "tree")
        if tree is None:
            raise JournalError(f"{folder}: the journal kept no state of the tree: it cannot be resumed")
        point.tree = tree[2]
        point.settled = {name: why for seq, name, why in done if tree[0] < seq}
        point.edits = _edits(journal, [s.segment for s in live], tree[0])
    else:
        _edits(journal, [s.segment for s in live], stop_seq)  # a program takes skip only; one loaded is refused
        point.calls, point.pending = _calls(journal, stop_seq)
        if point.pending is not None:
            _settle_pending(point, journal, done)
    reached = set(point.settled) | ({behavior_of(point.settled_call)} if point.settled_call else set())
    if LAND in reached:  # the last thing done was landing: the mission left the drone on the ground
        point.was_flying = False
    elif TAKE_OFF in reached:
        point.was_flying = True
    point.where()  # a stop the journal cannot say (a damaged one) is found here, not when the resume says it
    return point


def _edits(journal: Journal, segments: list[int], before: int) -> list[dict[str, Any]]:
    """The edits of the changes made to the tree in flight before its state was kept (``mission_change``), in
    order; JournalError for a mission replaced in flight (``load``): that one is flown again from its start."""
    edits: list[dict[str, Any]] = []
    places = ", ".join("?" * len(segments))
    for r in journal.rows(f"SELECT time, record FROM events WHERE kind = 'mission_change' AND seq < ? AND segment IN "
                          f"({places}) ORDER BY seq", (before, *segments)):
        data = json.loads(r["record"]).get("data") or {}
        if not data.get("ok"):
            continue
        if data.get("command") == "load":
            raise JournalError(f"{journal.path.parent}: the mission was replaced in flight at t={r['time']:.1f} s "
                               f"(load {data.get('argument', '')}): fly that one from its start (aeroexec run FILE)")
        edits.extend(data.get("edits") or [])
    return edits


def _effects(journal: Journal, segment: int, stop_seq: int) -> list[tuple[int, str, tuple[str, Any]]]:
    """``(seq, behavior, (why, result))`` of every goal reached (or work done) by the mission's behaviors."""
    rows = journal.rows("SELECT seq, kind, behavior, detail, record FROM events WHERE segment = ? AND seq < ? AND "
                        f"(kind = '{ACHIEVED}' OR kind IN ({', '.join(repr(k) for k in EFFECTS)})) ORDER BY seq",
                        (segment, stop_seq))
    found = []
    for r in rows:
        record = json.loads(r["record"])
        if r["kind"] == ACHIEVED and (record.get("data") or {}).get("source") not in ("mission", None):
            continue
        if r["kind"] != ACHIEVED and EFFECTS[r["kind"]] != r["behavior"]:
            continue
        result = record.get("result", r["detail"] if r["kind"] == "photo_taken" else None)
        found.append((r["seq"], r["behavior"], (f"{r['kind']} at t={record.get('time', 0.0):.1f} s", result)))
    return found


def _beliefs(journal: Journal, segment: int, stop_seq: int) -> list[tuple[str, float | None]]:
    held: dict[str, float | None] = {}
    for r in journal.rows("SELECT change, belief, predicate, expires_at FROM beliefs WHERE segment = ? AND seq < ? "
                          "ORDER BY seq", (segment, stop_seq)):
        if r["predicate"] in TELEMETRY_PREDICATES:
            continue
        if r["change"] == "added":
            held[r["belief"]] = r["expires_at"]
        else:
            held.pop(r["belief"], None)
    return list(held.items())


def _active(journal: Journal, segment: int, stop_seq: int) -> list[dict[str, Any]]:
    """The behaviors of the mission (or the operator) active when it stopped."""
    rows = journal.rows("SELECT * FROM behaviors WHERE segment = ? AND seq < ? AND source IN ('mission', 'operator') "
                        "AND (ended_seq IS NULL OR ended_seq >= ?) ORDER BY seq", (segment, stop_seq, stop_seq))
    return [{"behavior": r["behavior"], "arguments": json.loads(r["arguments"]), "source": r["source"],
             "priority": r["priority"] or "deliberative"} for r in rows]


def _calls(journal: Journal, stop_seq: int) -> tuple[list[RecordedCall], RecordedCall | None]:
    """The mission's completed calls before the stop, numbered 1, 2... (the calls that act or wait, and the runs
    of looking calls), and the first call that has no kept result (under way, or returned after the stop)."""
    found: list[tuple[int, int, RecordedCall]] = []
    for r in journal.rows("SELECT * FROM calls WHERE superseded = 0"):
        kept = r["returned_at"] is not None and not r["after_stop"] and r["seq"] < stop_seq
        found.append((r["number"], r["seq"], RecordedCall(
            r["number"], r["function"], r["arguments"], r["location"], r["requested_at"], kept,
            json.loads(r["result"]) if r["result"] is not None else None,
            json.loads(r["error"]) if r["error"] else None)))
    for r in journal.rows("SELECT * FROM looks WHERE superseded = 0"):
        calls = json.loads(r["calls"])
        kept = not r["after_stop"] and r["seq"] < stop_seq
        for n, index in enumerate(zlib.decompress(r["sequence"])[:r["count"]]):
            function, arguments, location, result = calls[index]
            found.append((r["first"] + n, r["seq"], RecordedCall(
                r["first"] + n, function, canonical(arguments), location, r["returned_at"], kept, result)))
    done: list[RecordedCall] = []
    for number, _, call in sorted(found, key=lambda item: item[:2]):
        if number <= len(done):
            continue  # kept twice: the first is taken
        if number != len(done) + 1:
            break  # a gap: what follows was not kept whole
        if not call.returned:
            return done, call
        done.append(call)
    return done, None


def behavior_of(call: RecordedCall | None) -> str | None:
    """The behavior a call of a Python mission asks for (None for ``wait`` and the calls that ask for none)."""
    if call is None or call.function == "wait":
        return None
    args = json.loads(call.arguments)[0]
    return str(args[0]).upper() if args else None


def _settle_pending(point: ResumePoint, journal: Journal, done: list[tuple[int, str, tuple[str, Any]]]) -> None:
    """The call under way whose behavior reached its goal after it was asked for returns that, replayed."""
    call = point.pending
    behavior = behavior_of(call)
    if call is None or call.function not in ("execute_behavior", "ask_behavior", "run_behavior") or not behavior:
        return
    asked = journal.rows("SELECT seq FROM calls WHERE number = ? AND superseded = 0 ORDER BY seq DESC LIMIT 1",
                         (call.number,))
    after = asked[0]["seq"] if asked else 0
    reached = next((why for seq, name, why in done if name == behavior and seq > after), None)
    if reached is None:
        return
    outcome = Outcome.GOAL_ACHIEVED
    result = {"execute_behavior": outcome, "ask_behavior": reached[1], "run_behavior": (True, outcome)}[call.function]
    point.settled_call = RecordedCall(call.number, call.function, call.arguments, call.location, call.requested_at,
                                      True, encode(result))
    point.calls.append(point.settled_call)
    point.pending = None




def resume_spec(folder: str | Path, *, mission: str | Path | None = None, drone: str | None = None,
                token: str | None = None, credentials: str | None = None, **flight: Any) -> Any:
    """The flight that goes on with the interrupted run in ``folder``: as it was asked (mission, robot, drone,
    world, catalog, plugins, seed, fleet), with ``flight``'s pacing, time limit, answers and surfaces (this
    command line's), and when given another ``mission`` file (the same mission moved: its content is checked when
    the flight opens), ``drone`` address or fleet ``credentials``; JournalError naming the journal when it cannot
    say (a damaged journal)."""
    from aeroexec.fleet.fleet_json import TOKEN_VARIABLE, read_fleet_file
    from aeroexec.flight.spec import FleetJoin, FlightSpec

    folder = Path(folder)
    with Journal(folder) as journal:
        meta = journal.meta()
        where = journal.path
    asked = meta.get("spec")
    if not isinstance(asked, dict):
        raise JournalError(f"{where}: the journal is damaged: it does not say what flight it was (meta 'spec')")
    mission = mission or meta.get("mission") or asked.get("mission")
    missing = [key for key, value in (("mission", mission), ("robot", asked.get("robot")),
                                      ("drone", drone or asked.get("drone"))) if not value]
    if missing:
        raise JournalError(f"{where}: the journal is damaged: its flight (meta 'spec') does not say its "
                           f"{' or '.join(missing)}: it cannot be resumed")
    try:
        fleet = asked.get("fleet")
        join = None
        if isinstance(fleet, dict):
            if token is None:
                try:
                    token = read_fleet_file(fleet["fleet"], str(folder)).get("token")
                except ValueError:
                    token = os.environ.get(TOKEN_VARIABLE)
            join = FleetJoin(fleet["fleet"], fleet["name"], tuple(fleet.get("connect") or ()), token,
                             tuple(fleet.get("share") or ()), float(fleet.get("telemetry_rate", 5.0)),
                             credentials or fleet.get("credentials"),
                             tuple((str(p), int(k)) for p, k in fleet.get("trust") or ()))
        return FlightSpec(mission=Path(mission), robot=str(asked["robot"]), drone=str(drone or asked["drone"]),
                          world=asked.get("world"), catalog=asked.get("catalog"), vehicle=asked.get("vehicle"),
                          library=tuple(asked.get("library") or ()), processes=tuple(asked.get("processes") or ()),
                          updaters=tuple(asked.get("updaters") or ()), rules=tuple(asked.get("rules") or ()),
                          safety_rules=tuple(asked.get("safety_rules") or ()), seed=int(asked.get("seed", 0)),
                          output=str(folder),
                          home=tuple(asked["home"]) if asked.get("home") else None,  # type: ignore[arg-type]
                          log=asked.get("log"), fleet=join, resume=True, **flight)
    except KeyError as error:
        raise JournalError(f"{where}: the journal is damaged: its flight (meta 'spec') does not say {error}: it "
                           f"cannot be resumed") from None
    except (TypeError, ValueError) as error:
        raise JournalError(f"{where}: the journal is damaged: its flight (meta 'spec') cannot be read "
                           f"({error}): it cannot be resumed") from None


__all__ = ["EFFECTS", "ResumePoint", "behavior_of", "resume_point", "resume_spec"]
