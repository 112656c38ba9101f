"""One behavior request made from a mission's thread that the mission may wait for, poll or stop: what a
non-blocking call of Aerostack2's Python API (``wait=False``, then ``status``/``wait_to_result()``) needs.

Every look at it is a call to the engine (polling lets simulated time move, as :mod:`.bridge` says); it
ends with the behavior's outcome (Table 2), FAILED_PRECONDITIONS when the activation was refused.
"""

from __future__ import annotations

from typing import Any

from aeroexec.engine import api
from aeroexec.engine.events import Outcome


class BehaviorRun:
    """A request of ``name`` with ``arguments`` on the engine this thread talks to, checked at once
    (:class:`~aeroexec.engine.errors.RequestRejected` at the mission's line for what verify would refuse)."""

    def __init__(self, name: str, **arguments: Any) -> None:
        self.engine = api.current_engine()
        self.name, self.arguments, self.options = api.checked_request(name, **arguments)
        self.accepted: bool | None = None  # None until started
        self.outcome: Outcome | None = None
        self.value: Any = None
        self._resolve: Any = None
        self._activation: Any = None

    def start(self) -> bool:
        """Ask for the behavior; True when the activation was accepted."""
        return self.engine.bridge.call(self.activate)

    def activate(self) -> bool:
        """:meth:`start` on the engine's thread."""
        result = self.engine.coordinator.activate(self.name, self.arguments, timeout=self.options.get("timeout"),
                                                  source="mission", on_end=self._ended)
        self.accepted, self._activation = result.accepted, result.activation
        if not result.accepted:
            self.outcome = result.outcome or Outcome.FAILED_PRECONDITIONS
        return result.accepted

    def _ended(self, outcome: Outcome, message: str, value: Any) -> None:  # on the engine's thread
        self.outcome, self.value = outcome, value
        if self._resolve is not None:
            self._resolve(outcome)

    def wait(self) -> Outcome:
        """Wait (on the engine's clock) until the behavior ends; its outcome."""
        if self.accepted is None:
            self.start()

        def register(resolve: Any) -> None:
            if self.outcome is not None:
                resolve(self.outcome)
            else:
                self._resolve = resolve

        return self.engine.bridge.wait_for(register)

    def running(self) -> bool:
        """True while the behavior runs (a call to the engine: a loop polling it sees time move)."""
        return bool(self.engine.bridge.call(lambda: self.accepted and self.outcome is None))

    def stop(self, reason: str = "stopped by the mission") -> bool:
        """End the behavior now (INTERRUPTED); False when it was not running."""
        engine = self.engine

        def stop() -> bool:
            if self.outcome is not None or engine.coordinator.active().get(self.name) is not self._activation:
                return False
            return engine.coordinator.stop(self.name, reason)

        return engine.bridge.call(stop)


class BehaviorQueue:
    """Items run one after another on the engine's thread, as Aerostack2's mission interpreter runs its plan: an
    item is the runs of one call (``rtl`` is GO_TO_POINT then LAND); the next item starts in the tick the one
    before ends, whatever its outcome (a run that fails ends its item). An item that could not be requested
    (None) ends the queue there, as a rejected goal stops the interpreter."""

    def __init__(self, engine: Any, items: list[list[BehaviorRun] | None]) -> None:
        self.engine, self.items = engine, items
        self.index = -1  # the item running now
        self._step = 0
        self.finished = False
        self._waiters: list[Any] = []

    def start(self, first: int = 0) -> None:
        """Start at item ``first`` (on the mission's thread)."""
        def begin() -> None:
            self.index = first - 1
            self._advance()
            if not self.finished:
                self.engine.tick_callbacks.append(self._tick)

        self.engine.bridge.call(begin)

    def _current(self) -> BehaviorRun | None:
        runs = self.items[self.index] if 0 <= self.index < len(self.items) else None
        return runs[self._step] if runs and self._step < len(runs) else None

    def _advance(self) -> None:
        """Start what comes after the current run (engine thread)."""
        while True:
            run = self._current()
            if run is not None and run.outcome is None:
                if run.accepted is None:
                    run.activate()
                    continue
                return  # running
            if run is not None and run.outcome is Outcome.GOAL_ACHIEVED and \
                    self._step + 1 < len(self.items[self.index] or ()):
                self._step += 1
                continue
            self.index, self._step = self.index + 1, 0
            if self.index >= len(self.items) or self.items[self.index] is None:
                self._finish()
                return

    def _finish(self) -> None:
        self.finished = True
        self.index = min(self.index, len(self.items))
        if self._tick in self.engine.tick_callbacks:
            self.engine.tick_callbacks.remove(self._tick)
        for resolve in self._waiters:
            resolve(None)
        self._waiters.clear()

    def _tick(self) -> None:
        if not self.finished:
            self._advance()

    def stop(self, reason: str = "stopped by the mission") -> None:
        """Stop the running item and end the queue."""
        def stop() -> None:
            run = self._current()
            self._finish()
            if run is not None and run.outcome is None and run.accepted:
                self.engine.coordinator.stop(run.name, reason)

        self.engine.bridge.call(stop)

    def skip(self) -> None:
        """Stop the running item; the next one starts."""
        def skip() -> None:
            run = self._current()
            if run is not None and run.outcome is None and run.accepted:
                self.engine.coordinator.stop(run.name, "the mission went on to its next item")

        self.engine.bridge.call(skip)

    def state(self) -> tuple[int, bool]:
        """(the index of the item running now, finished) — a call to the engine: polling lets time move."""
        return self.engine.bridge.call(lambda: (self.index, self.finished))

    def wait(self) -> None:
        """Wait until the last item has ended."""
        def register(resolve: Any) -> None:
            if self.finished:
                resolve(None)
            else:
                self._waiters.append(resolve)

        self.engine.bridge.wait_for(register)


__all__ = ["BehaviorQueue", "BehaviorRun"]
