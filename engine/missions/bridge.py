"""The bridge between a mission's thread and the engine's loop: calls run on the engine's thread, in lockstep.

A Python mission runs in its own thread. Each API call becomes a request the
engine executes between ticks; a call that waits (a behavior until it ends)
parks the mission until the engine resolves it. With a simulated clock the
engine does not advance time while the mission is running Python code, so a
mission gives the same event log on every run.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable
from typing import Any

from aeroexec.engine.errors import MissionAborted

logger = logging.getLogger(__name__)

RUNNING, PARKED, DONE = "running", "parked", "done"
_STALL_WARNING = 30.0  # wall seconds a lockstep engine waits on a busy mission before saying so


class _Request:
    __slots__ = ("function", "waits", "done", "value", "error")

    def __init__(self, function: Callable, waits: bool) -> None:
        self.function = function
        self.waits = waits
        self.done = threading.Event()
        self.value: Any = None
        self.error: BaseException | None = None


class MissionBridge:
    """Queues the mission thread's calls for the engine thread; tracks whether the mission runs or waits."""

    def __init__(self) -> None:
        self._queue: queue.SimpleQueue[_Request] = queue.SimpleQueue()
        self._cond = threading.Condition()
        self._state = DONE
        self._pending: set[_Request] = set()
        self._closed = False
        self._held = False

    # -- the mission's side ------------------------------------------------------------
    def call(self, function: Callable[[], Any]) -> Any:
        """Run ``function`` on the engine thread and return its value (or raise its exception)."""
        return self._submit(_Request(function, waits=False))

    def wait_for(self, register: Callable[[Callable[[Any], None]], None]) -> Any:
        """Run ``register(resolve)`` on the engine thread; block until the engine calls ``resolve(value)``."""
        return self._submit(_Request(register, waits=True))

    def _submit(self, request: _Request) -> Any:
        if self._closed:
            raise MissionAborted("the engine has stopped")
        with self._cond:
            self._queue.put(request)
            self._cond.notify_all()
        while not request.done.wait(0.5):
            if self._closed:
                raise MissionAborted("the engine has stopped")
        if request.error is not None:
            raise request.error
        return request.value

    def mission_started(self) -> None:
        with self._cond:
            self._state = RUNNING
            self._closed = False

    def mission_finished(self) -> None:
        with self._cond:
            self._state = DONE
            self._cond.notify_all()

    # -- the engine's side ---------------------------------------------------------------
    @property
    def state(self) -> str:
        return self._state

    @property
    def queued(self) -> int:
        """How many of the mission's calls wait to be served (while paused, the mission's next call does)."""
        return self._queue.qsize()

    def hold(self, held: bool) -> None:
        """While held (the operator paused), :meth:`serve` runs nothing: the mission's next call waits."""
        with self._cond:
            self._held = held
            self._cond.notify_all()

    def serve(self, lockstep: bool, until_wall: float | None = None) -> None:
        """Execute queued calls. In lockstep, return only when the mission waits or is done;
        otherwise return at ``until_wall`` (a ``time.monotonic`` deadline) or when nothing is queued."""
        warned_at = time.monotonic() + _STALL_WARNING
        while not self._held:
            try:
                request = self._queue.get_nowait()
            except queue.Empty:
                request = None
            if request is not None:
                self._execute(request)
                continue
            with self._cond:
                if lockstep and self._state == RUNNING:
                    self._cond.wait(0.05)
                    if time.monotonic() > warned_at:
                        logger.warning("the mission has been busy for %.0f s of wall time without calling the "
                                       "engine; simulated time waits for it", _STALL_WARNING)
                        warned_at = time.monotonic() + _STALL_WARNING
                    continue
                if until_wall is None or time.monotonic() >= until_wall:
                    return
                self._cond.wait(min(0.05, max(0.0, until_wall - time.monotonic())))

    def _execute(self, request: _Request) -> None:
        if not request.waits:
            try:
                request.value = request.function()
            except BaseException as exc:  # handed to the mission thread, which raises it
                request.error = exc
            request.done.set()
            return
        with self._cond:
            self._state = PARKED
            self._pending.add(request)

        def resolve(value: Any) -> None:
            with self._cond:
                if request not in self._pending:
                    return
                self._pending.discard(request)
                request.value = value
                self._state = RUNNING
                request.done.set()

        try:
            request.function(resolve)
        except BaseException as exc:
            with self._cond:
                self._pending.discard(request)
                request.error = exc
                self._state = RUNNING
                request.done.set()

    def close(self) -> None:
        """Abort every waiting call: the mission thread raises :class:`MissionAborted`."""
        with self._cond:
            self._closed = True
            for request in self._pending:
                request.error = MissionAborted("the engine has stopped")
                request.done.set()
            self._pending.clear()
            self._cond.notify_all()
        while True:
            try:
                request = self._queue.get_nowait()
            except queue.Empty:
                break
            request.error = MissionAborted("the engine has stopped")
            request.done.set()
