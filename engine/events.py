"""Behavior events and execution results (paper section 4.1, Table 2), and the engine's event log.

Every decision the engine takes is an :class:`EngineEvent` with the simulated
or wall time, what happened, to which behavior and why; the log is what the
operator reads and what makes two runs comparable.
"""

from __future__ import annotations

import enum
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger("aeroexec.events")


class Outcome(enum.StrEnum):
    """How a behavior request ended (the events of section 4.1 and the results of Table 8)."""

    GOAL_ACHIEVED = "GOAL_ACHIEVED"
    TIME_OUT = "TIME_OUT"
    WRONG_PROGRESS = "WRONG_PROGRESS"
    INTERRUPTED = "INTERRUPTED"
    FAILED_PRECONDITIONS = "FAILED_PRECONDITIONS"


#: The paper's Table 8 calls the success result ACHIEVED_GOAL; both names mean the same.
ACHIEVED_GOAL = Outcome.GOAL_ACHIEVED


def failed_preconditions_message(behavior: str) -> str:
    return f"Behavior {behavior} cannot be executed because its preconditions are not satisfied."


def time_out_message(behavior: str, seconds: float) -> str:
    return f"The goal of behavior {behavior} has not been reached in the expected time ({seconds:g} seconds)"


def wrong_progress_message(behavior: str) -> str:
    return f"The behavior {behavior} does not progress correctly"


def achieved_goal_message(behavior: str) -> str:
    return f"The goal of behavior {behavior} has already been achieved"


@dataclass(frozen=True, slots=True)
class EngineEvent:
    """One thing the engine did or saw: ``kind`` is e.g. activated, GOAL_ACHIEVED, rejected, capability_started."""

    time: float
    kind: str
    behavior: str = ""
    detail: str = ""
    data: dict[str, Any] = field(default_factory=dict)

    def __str__(self) -> str:
        who = f" {self.behavior}" if self.behavior else ""
        what = f": {self.detail}" if self.detail else ""
        return f"[{self.time:8.2f}] {self.kind}{who}{what}"


#: Refusals that repeat identically are recorded once, then counted (a mission polling a refused behavior).
REPEATED_KINDS = ("failed_preconditions", "rejected")
#: Engine seconds between two counts of a refusal that keeps repeating.
REPEAT_REPORT = 60.0


@dataclass
class _Repeats:
    """An identical refusal seen again: how many times since it was last recorded or counted, first and last time."""

    count: int = 0
    first: float = 0.0
    last: float = 0.0
    since: float = 0.0  # when it was last recorded or counted


class EventLog:
    """The ordered events of a run; listeners hear each one as it is recorded (on the engine's thread).

    A refusal identical to the last one of its behavior (same kind and reason) is not recorded again: it is
    counted, and the count is recorded as one event (``repeated=N``) when something else happens to the
    behavior, every :data:`REPEAT_REPORT` seconds, and when the mission or the engine ends."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        self._events: list[EngineEvent] = []
        self._listeners: list[Callable[[EngineEvent], None]] = []
        self._lock = threading.Lock()
        self._refused: dict[str, tuple[tuple[str, str], _Repeats]] = {}  # behavior -> (kind, detail), repeats

    def record(self, kind: str, behavior: str = "", detail: str = "", *, at: float | None = None,
               **data: Any) -> EngineEvent:
        """Record an event that happened now, or ``at`` an earlier time of the same clock (a robot's own report)."""
        now = self._clock() if at is None else at
        if behavior and kind in REPEATED_KINDS:
            key = (kind, detail)
            last = self._refused.get(behavior)
            if last is not None and last[0] == key:
                repeats = last[1]
                if not repeats.count:
                    repeats.first = now
                repeats.count, repeats.last = repeats.count + 1, now
                if now - repeats.since < REPEAT_REPORT:
                    return EngineEvent(now, kind, behavior, detail, data)  # counted, not recorded again
                self._counted(behavior)
                return EngineEvent(now, kind, behavior, detail, data)
            self._counted(behavior)
            self._refused[behavior] = (key, _Repeats(since=now))
        elif behavior and behavior in self._refused:
            self._counted(behavior, forget=True)
        elif kind.startswith(("mission_", "engine_", "run_")):
            for name in list(self._refused):
                self._counted(name, forget=True)
        return self._append(EngineEvent(now, kind, behavior, detail, data))

    def _counted(self, behavior: str, forget: bool = False) -> None:
        """Record how many times the last refusal of ``behavior`` repeated since it was last said."""
        last = self._refused.pop(behavior, None) if forget else self._refused.get(behavior)
        if last is None or not last[1].count:
            return
        (kind, detail), repeats = last
        self._append(EngineEvent(self._clock(), kind, behavior, f"the same refusal {repeats.count} more time"
                                 f"{'s' if repeats.count != 1 else ''} (t={repeats.first:.2f} to {repeats.last:.2f})",
                                 {"repeated": repeats.count, "reason": detail}))
        repeats.count, repeats.since = 0, self._clock()

    def _append(self, event: EngineEvent) -> EngineEvent:
        with self._lock:
            self._events.append(event)
            listeners = list(self._listeners)
        logger.debug("%s", event)
        for listener in listeners:
            try:
                listener(event)
            except Exception:
                logger.exception("an event listener failed on %s", event)
        return event

    def subscribe(self, listener: Callable[[EngineEvent], None]) -> Callable[[], None]:
        """Hear every future event; returns a function that unsubscribes."""
        with self._lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    def events(self, kind: str | None = None, behavior: str | None = None) -> list[EngineEvent]:
        with self._lock:
            return [e for e in self._events
                    if (kind is None or e.kind == kind) and (behavior is None or e.behavior == behavior)]

    def __len__(self) -> int:
        return len(self._events)
