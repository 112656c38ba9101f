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


class EventLog:
    """The ordered events of a run; listeners hear each one as it is recorded (on the engine's thread)."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        self._events: list[EngineEvent] = []
        self._listeners: list[Callable[[EngineEvent], None]] = []
        self._lock = threading.Lock()

    def record(self, kind: str, behavior: str = "", detail: str = "", *, at: float | None = None,
               **data: Any) -> EngineEvent:
        """Record an event that happened now, or ``at`` an earlier time of the same clock (a robot's own report)."""
        event = EngineEvent(self._clock() if at is None else at, kind, behavior, detail, data)
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
