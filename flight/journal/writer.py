"""Writing a run's flight journal as it flies (the schema: ``schema.py``).

The engine's thread (and a Python mission's, for its calls) appends rows to a list; the loop commits the list in
one transaction (``store.py``: no wait for the disk, the checkpoints are another thread's) in the tick after a
behavior event, a node transition, an operator command, a mission call that acts or a tree state was recorded
(:meth:`JournalWriter.on_tick`, before the mission's part of the tick), so a ``kill -9`` loses at most the last
engine period; otherwise every ``FLUSH_PERIOD`` s of engine time (telemetry, belief changes, polling calls). A
journal that cannot be written (a full disk) stops with :attr:`JournalWriter.incomplete` set and the flight goes
on.

Where the mission stopped is kept as it happens (``progress`` ``stop``): a reaction of the higher priority that
takes the drone from the mission (LAND on low battery), ``ctl suspend`` or ``ctl abort`` (``mission_stopped``),
Ctrl-C (``operator_interrupt``), the time limit. From then on the tree's state is not written again and the
mission's calls are marked ``after_stop``, so a resume goes on from the stop, not from what the ending did. A
reaction after which the mission achieves a goal again (it went on by itself) lifts the stop.
"""

from __future__ import annotations

import datetime
import itertools
import json
import logging
import re
import threading
from pathlib import Path

from aeroexec.beliefs import BeliefChange
from aeroexec.engine.events import EngineEvent, Outcome
from aeroexec.flight.flight_log import (
    SAMPLE_PERIOD,
    belief_line,
    event_line,
    event_record,
    plain,
    state_line,
)
from aeroexec.flight.journal.schema import journal_path
from aeroexec.flight.journal.store import JournalStore, Row
from aeroexec.flight.run_status import HIGHER, REACTION, safety_reaction

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.flight.journal.looks import LookRun

logger = logging.getLogger(__name__)

FLUSH_PERIOD = 5.0  # s of engine time between two commits when nothing urgent happened
TREE_PERIOD = 5.0  # s of engine time between two tree states when nothing visible changed (counters, timers)
#: The robot's own motion beliefs, changing every belief period: kept as telemetry samples instead.
MOTION = frozenset({"position", "speed", "orientation"})
#: Events where the mission stops (besides a reaction of the higher priority).
STOPS = frozenset({"mission_stopped", "mission_suspended", "operator_interrupt", "engine_time_limit"})
#: Calls that only look: not worth a commit of their own.
LOOKS = frozenset({"consult_belief", "true_belief", "is_active_behavior", "now", "why", "why_not"})
OUTCOMES = frozenset(o.value for o in Outcome)
#: Events that need no commit of their own (the next one takes them): capabilities, the drone's own reports.
BACKGROUND = ("capability_", "drone_")
_TAKEN_OVER = re.compile(r"^stopped for (\S+) \(reactive\)$")

_EVENT = "INSERT INTO events VALUES (?, ?, ?, ?, ?, ?, ?, NULL)"  # a record that does not expire (nearly all)
# a None bound to a statement is looked up as an adapter's (~3,000 instructions, a failed attribute look-up): NULL is
# written in the statement instead
_EXPIRING = "INSERT INTO events VALUES (?, ?, ?, ?, ?, ?, ?, ?)"  # a belief that lasts a while: when it expires
_CALLED = "INSERT INTO calls VALUES (?, ?, ?, ?, ?, ?, ?, NULL, NULL, NULL, 0, 0)"  # a call requested, not returned
_ACTIVATED = "INSERT INTO behaviors VALUES (?, ?, ?, ?, ?, ?, ?, NULL, NULL, NULL, NULL, NULL)"
_REFUSED = "INSERT INTO behaviors VALUES (?, ?, ?, '{}', ?, NULL, ?, ?, ?, ?, ?, ?)"
_ENDED = "UPDATE behaviors SET ended_seq = ?, ended_at = ?, outcome = ?, message = ?, result = ? WHERE seq = ?"
_CALL = "INSERT INTO calls VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, 0)"
_RETURNED = "UPDATE calls SET returned_at = ?, result = ?, error = ?, after_stop = ? WHERE seq = ?"
_LOOKS = "INSERT OR REPLACE INTO looks VALUES (?, ?, ?, ?, ?, ?, ?, ?, 0)"
_PROGRESS = "INSERT OR REPLACE INTO progress VALUES (?, ?, ?, ?, ?)"
_NO_PROGRESS = "DELETE FROM progress WHERE segment = ? AND key = ?"


class JournalWriter:
    """Journals ``engine``'s run into ``folder``'s journal as one new segment (the first, or a resume's).

    ``meta`` is written when the journal is new (the flight as asked); ``supersede_from``: a resumed Python
    mission's first live call number (the interrupted run's calls from there on are marked superseded when the
    mission goes live)."""

    def __init__(self, engine: Any, folder: str | Path, *, meta: dict[str, Any] | None = None,
                 supersede_from: int | None = None, sample_period: float = 2 * SAMPLE_PERIOD) -> None:
        self.engine = engine
        self._clock = engine.clock  # the engine's time (Engine.now, without its call)
        self.path = journal_path(folder)
        self.sample_period = sample_period
        self.supersede_from = supersede_from
        self.live = False
        self.frozen: dict[str, Any] | None = None  # where the mission stopped, once it did
        self._store = JournalStore(self.path)
        try:
            self.segment, start = self._begin(meta or {})
        except BaseException:
            self._store.close()
            raise
        self._seq = itertools.count(start).__next__
        self._rows: list[Row] = []
        self._rows_lock = threading.Lock()
        self._urgent = False
        self._next_flush = engine.now() + FLUSH_PERIOD
        self._last_sample: float | None = None  # the last sample's time, and the last periodic one's
        self._last_periodic: float | None = None
        self._active: dict[str, tuple[int, bool]] = {}  # behavior -> its open activation row, and whether urgent
        self._waiting: dict[int, int] = {}  # call number -> its row, while under way
        self._looks: LookRun | None = None  # the run of looking calls going on
        self._mission_running = False
        self._reaction: str | None = None  # the reaction that stopped the mission
        self._tree: Any = None
        self._capture: Any = None  # the tree's Capture
        self._tree_dirty = True
        self._shape_kept = False
        self._tree_writes = -1
        self._next_tree = self._next_look = 0.0
        self._closed = False
        self._status: Any = None
        self._code: int | None = None  # the exit status the run ends with (None: its status's)
        self._unsubscribe = [engine.log.subscribe(self.on_event), engine.memory.subscribe(self.on_belief)]
        engine.tick_callbacks.append(self.on_tick)

    @property
    def incomplete(self) -> str | None:
        """Why the journal stopped short (the write's error), None while it is whole."""
        return self._store.incomplete

    def _begin(self, meta: dict[str, Any]) -> tuple[int, int]:
        db = self._store.db
        with db:
            for key, value in meta.items():
                db.execute("INSERT OR IGNORE INTO meta VALUES (?, ?)",
                           (key, value if isinstance(value, str) else json.dumps(plain(value))))
            segment = (db.execute("SELECT max(segment) FROM segments").fetchone()[0] or 0) + 1
            db.execute("INSERT INTO segments (segment, started_wall, started_at) VALUES (?, ?, ?)",
                       (segment, datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
                        round(self.engine.now(), 3)))
            last = max(db.execute(f"SELECT max(seq) FROM {table}").fetchone()[0] or 0
                       for table in ("events", "behaviors", "calls", "looks", "progress"))
        return segment, last + 1

    # -- the engine's side ------------------------------------------------------------------------------------
    def on_event(self, event: EngineEvent) -> None:
        seq = self._seq()
        time = round(event.time, 3)
        kind, name, data = event.kind, event.behavior, event.data
        rows = [(_EVENT, (seq, self.segment, time, kind, name, event.detail, event_line(event)))]
        source = data.get("source", "")
        urgent = not kind.startswith(BACKGROUND)
        if kind == "activated":
            urgent = source != "reactive" or data.get("priority") != "lower"  # a background reaction waits
            self._active[name] = (seq, urgent)
            rows.append((_ACTIVATED, (seq, self.segment, name, json.dumps(plain(data.get("arguments", {}))), source,
                                      data.get("priority"), time)))
        elif kind in OUTCOMES or kind in ("failed_preconditions", "rejected"):
            outcome = kind if kind in OUTCOMES else Outcome.FAILED_PRECONDITIONS.value
            result = json.dumps(plain(data["result"])) if data.get("result") is not None else None
            opened, urgent = self._active.pop(name, (None, True)) if kind in OUTCOMES else (None, True)
            if opened is not None:
                rows.append((_ENDED, (seq, time, outcome, event.detail, result, opened)))
            else:  # refused, or its goal already achieved: a request that never ran
                rows.append((_REFUSED, (seq, self.segment, name, source, time, seq, time, outcome, event.detail,
                                        result)))
        elif kind == REACTION:
            urgent = HIGHER in event.detail
        self._add(rows, urgent=urgent)
        if kind == "node_status" or kind in OUTCOMES:
            self._tree_dirty = True
        if kind in OUTCOMES and source == "mission" and self._last_sample != time:
            self.sample()  # where the drone was when a behavior of the mission ended: where a resume puts it
        self._watch(seq, event, source)

    def on_belief(self, change: BeliefChange) -> None:
        belief = change.belief
        if belief.name in MOTION and belief.args and belief.args[0] == "self":
            return
        if change.reason == "shared":  # a fleet mate's position came or went: not this drone's state (a resume
            return  # hears it again from the fleet); its fleet_drone_heard event says so, as in events.jsonl
        lifetime = self.engine.memory.lifetime(belief.name) if change.kind == "added" else None
        time = round(float(change.time), 3)
        row = (self._seq(), self.segment, time, f"belief_{change.kind}", "", "", belief_line(change))
        self._add([(_EVENT, row) if lifetime is None else (_EXPIRING, (*row, round(time + lifetime, 3)))])

    def on_tick(self) -> None:
        # Registered before a tree's tick (and a Python mission's calls, served after the tick): a commit holds what
        # the mission did in the last period with the behavior events of this tick that settle it (a broadcast sent
        # and its goal reached), so a resume never sees the one without the other. Keep it first.
        now = self._clock.now()
        last = self._last_periodic
        if last is None or now - last >= self.sample_period - 1e-9:
            self._last_periodic = now  # as events.jsonl samples: at the same times
            self.sample(now)
        if self._urgent or now >= self._next_flush:
            self.flush()

    def sample(self, now: float | None = None) -> str | None:
        """Write the drone's state now (the event log's line of it, made once for both); the line (None when the
        drone cannot say)."""
        now = self.engine.now() if now is None else now
        self._last_sample = round(now, 3)
        try:
            telemetry = self.engine.drone.telemetry()
            line = state_line(now, telemetry)
        except Exception:  # a drone that cannot answer: no sample, the journal goes on
            logger.exception("no drone state for the journal")
            return None
        self._add([(_EVENT, (self._seq(), self.segment, self._last_sample, "state", "", "", line))])
        return line

    # -- a tree mission ---------------------------------------------------------------------------------------
    def attach_tree(self, mission: Any) -> None:
        """Keep ``mission``'s state (after each tick that changed it) while the mission is live."""
        from aeroexec.trees.runtime.tree_state import Capture

        self._tree = mission
        self._capture = Capture(mission.root, mission.blackboard)
        mission.observers.append(self._tree_ticked)
        getattr(mission, "restructured", []).append(self._restructured)

    def _restructured(self) -> None:
        """The tree was changed in flight: its next state is kept with its new shape."""
        from aeroexec.trees.runtime.tree_state import Capture

        self._capture = Capture(self._tree.root, self._tree.blackboard)
        self._shape_kept, self._tree_dirty = False, True

    def _tree_ticked(self, visited: Any) -> None:
        if visited is None or not self.live or self.frozen is not None:
            return  # halted (the ending), not live yet, or stopped: the state kept is the one to resume
        now = self.engine.now()
        if not self._tree_dirty and now >= self._next_look:  # the blackboard alone changed? looked at twice a second
            self._next_look = now + self.sample_period
            writes = sum(sum(board._versions.values()) for board in self._capture.boards)
            self._tree_dirty, self._tree_writes = writes != self._tree_writes, writes
        if self._tree_dirty or now >= self._next_tree:
            self.keep_tree(now)

    def keep_tree(self, now: float | None = None) -> None:
        """Write the tree's state now."""
        now = self.engine.now() if now is None else now
        self._tree_dirty = False
        self._next_tree = now + TREE_PERIOD
        state = self._capture()
        rows = [(_PROGRESS, (self.segment, "tree", self._seq(), round(now, 3), state.to_json(shape=False)))]
        if not self._shape_kept:  # the tree's shape once (resume_point reads its states with it)
            self._shape_kept = True
            rows.append(("INSERT OR REPLACE INTO meta VALUES ('tree_shape', ?)", (json.dumps(state.shape()),)))
        self._add(rows, urgent=True)

    # -- a Python mission's calls (on its thread) --------------------------------------------------------------
    def call_requested(self, number: int, function: str, arguments: str, location: str, time: float) -> None:
        seq = self._seq()
        self._waiting[number] = seq
        self._add([(_CALLED, (seq, self.segment, number, function, arguments, location, round(time, 3)))],
                  urgent=True, looks_end=True)

    def call_returned(self, number: int, function: str, arguments: str, location: str, time: float,
                      result: str | None, error: dict[str, Any] | None) -> None:
        after = int(self.frozen is not None)
        if error is None and function in LOOKS:  # a polling loop's call: a byte in the run of looks
            key = (function, arguments, location, result)
            with self._rows_lock:
                looks = self._looks
                if looks is None or not looks.add(number, after, key, time):
                    if looks is not None and looks.dirty:
                        self._rows.append((_LOOKS, looks.row(self.segment)))
                    from aeroexec.flight.journal.looks import LookRun  # here: a mission that never looks needs none

                    looks = self._looks = LookRun(self._seq(), number, after)
                    looks.add(number, after, key, time)
            return
        time = round(time, 3)
        answer = None if error is not None else result
        failure = None if error is None else json.dumps(error)
        row = self._waiting.pop(number, None)
        if row is not None:
            self._add([(_RETURNED, (time, answer, failure, after, row))], urgent=True)
            return
        self._add([(_CALL, (self._seq(), self.segment, number, function, arguments, location, time, time, answer,
                            failure, after))], urgent=True, looks_end=True)

    # -- the mission's course ---------------------------------------------------------------------------------
    def went_live(self) -> None:
        """The mission runs live from now on (after a resume's replay and rejoin): its progress is kept."""
        if self.live:
            return
        self.live = True
        now = round(self.engine.now(), 3)
        rows: list[tuple[str, tuple]] = [("UPDATE segments SET live_at = ? WHERE segment = ?", (now, self.segment))]
        if self.supersede_from is not None:
            later = (self.segment, self.supersede_from)
            rows += [("UPDATE calls SET superseded = 1 WHERE segment < ? AND number >= ? AND superseded = 0", later),
                     ("UPDATE looks SET superseded = 1 WHERE segment < ? AND first >= ? AND superseded = 0", later),
                     ("UPDATE looks SET count = ? - first WHERE segment < ? AND first < ? AND first + count > ? AND "
                      "superseded = 0", (self.supersede_from, *later, self.supersede_from))]
        self._add(rows, urgent=True)
        if self._tree is not None:
            self.keep_tree()

    def _watch(self, seq: int, event: EngineEvent, source: str) -> None:
        kind = event.kind
        if kind == "mission_started":
            self._mission_running = True
        elif kind in ("mission_completed", "mission_failed"):
            self._mission_running = False
        if self.frozen is None:
            taken = _TAKEN_OVER.match(event.detail) if kind == Outcome.INTERRUPTED.value else None
            if kind in STOPS:
                self._freeze(seq, event, event.detail or kind)
            elif taken is not None and source == "mission":
                self._reaction = taken.group(1)
                self._freeze(seq, event, f"{taken.group(1)} took the drone over (a reaction of the higher priority)")
            elif kind == REACTION and HIGHER in event.detail and self._mission_running:
                self._reaction = event.behavior
                self._freeze(seq, event, safety_reaction([event_record(event)]) or event.detail)
        elif kind == REACTION and self._reaction == event.behavior and self.frozen["kind"] == Outcome.INTERRUPTED:
            self.frozen["kind"] = REACTION  # the reaction says what took over, and why
            self.frozen["reason"] = safety_reaction([event_record(event)]) or self.frozen["reason"]
            self._keep_stop()
        elif (kind == Outcome.GOAL_ACHIEVED.value and source == "mission" and self._reaction is not None
              and not self.engine.coordinator.is_active(self._reaction)):
            self._unfreeze()  # the reaction is over and the mission went on by itself

    def _freeze(self, seq: int, event: EngineEvent, reason: str) -> None:
        line = self.sample()
        state = {k: v for k, v in json.loads(line).items() if k not in ("time", "kind")} if line else {}
        self.frozen = {"seq": seq, "time": round(event.time, 3), "kind": event.kind, "reason": reason,
                       "behavior": event.behavior, "drone": state}
        self._keep_stop()

    def _keep_stop(self) -> None:
        self._add([(_PROGRESS, (self.segment, "stop", self.frozen["seq"], self.frozen["time"],
                                json.dumps(self.frozen)))], urgent=True)

    def _unfreeze(self) -> None:
        stopped, self.frozen, self._reaction = self.frozen, None, None
        self._add([(_NO_PROGRESS, (self.segment, "stop")),
                   ("UPDATE calls SET after_stop = 0 WHERE segment = ? AND seq > ?", (self.segment, stopped["seq"])),
                   ("UPDATE looks SET after_stop = 0 WHERE segment = ? AND seq > ?", (self.segment, stopped["seq"]))],
                  urgent=True)
        self._tree_dirty = True

    # -- committing ------------------------------------------------------------------------------------------
    def _add(self, rows: list[Row], urgent: bool = False, looks_end: bool = False) -> None:
        with self._rows_lock:
            if looks_end and self._looks is not None:  # a call that acts or waits ends a run of looks
                if self._looks.dirty:
                    self._rows.append((_LOOKS, self._looks.row(self.segment)))
                self._looks = None
            self._rows.extend(rows)
            if urgent:
                self._urgent = True

    def flush(self) -> None:
        """Commit what was recorded, in one transaction."""
        with self._rows_lock:
            if self._looks is not None and self._looks.dirty:
                self._rows.append((_LOOKS, self._looks.row(self.segment)))
            rows, self._rows, self._urgent = self._rows, [], False
        self._next_flush = self.engine.now() + FLUSH_PERIOD
        if rows:
            self._store.write(rows)

    # -- the end ----------------------------------------------------------------------------------------------
    def ended(self, status: Any, code: int | None = None) -> None:
        """How the run ended (a RunStatus) and the exit status the process returns (default: the status's),
        written when the journal closes (after the engine's last events)."""
        self._status, self._code = status, code

    def close(self, status: Any = None) -> None:
        """End the segment (``status``, else the one :meth:`ended` gave: how the run ended), write everything,
        close (idempotent)."""
        if self._closed:
            return
        code = self._code if status is None else None
        status = status if status is not None else self._status
        self._stop_listening()
        self.sample()
        if status is not None:
            self._add([("UPDATE segments SET ended_at = ?, status = ?, exit_status = ?, reasons = ? "
                        "WHERE segment = ?", (round(self.engine.now(), 3), status.word,
                                              status.exit_status if code is None else code,
                                              json.dumps(list(status.reasons)), self.segment))])
        self._finish()

    def abandon(self) -> None:
        """Stop as a killed process would: what was committed is kept, nothing more (tests of a crash)."""
        if self._closed:
            return
        self._stop_listening()
        with self._rows_lock:
            self._rows = []
        self._finish()

    def _stop_listening(self) -> None:
        self._closed = True
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        if self.on_tick in self.engine.tick_callbacks:
            self.engine.tick_callbacks.remove(self.on_tick)
        if self._tree is not None and self._tree_ticked in self._tree.observers:
            self._tree.observers.remove(self._tree_ticked)

    def _finish(self) -> None:
        self.flush()
        self._store.close()


__all__ = ["FLUSH_PERIOD", "MOTION", "JournalWriter"]
