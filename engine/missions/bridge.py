"""The bridge between a mission's thread and the engine's loop: calls run on the engine's thread, in lockstep.

A Python mission runs in its own thread. Each API call becomes a request the
engine executes between ticks; a call that waits (a behavior until it ends)
parks the mission until the engine resolves it. With a simulated clock the
engine does not advance time while the mission is running Python code, so a
mission gives the same event log on every run; but every API call counts: after
``CALLS_PER_TICK`` calls that do not wait, the engine takes its next step, so a
mission polling ``trueBelief`` in a loop sees simulated time (and the world) move; a call that waits but
ends at once (a request refused, or a goal already achieved) lets the engine take its step before the next
call, so a mission asking again and again for a refused behavior still sees time pass, a tick per request.
A mission that keeps polling while no belief changes is reported once per stretch.
"""

from __future__ import annotations

import contextlib
import logging
import queue
import threading
import time
from collections.abc import Callable, Iterable

from aeroexec.engine.errors import MissionAborted

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

RUNNING, PARKED, DONE = "running", "parked", "done"
#: What :attr:`MissionBridge.state` says of a running mission that has made its ``CALLS_PER_TICK`` calls of this
#: engine period without waiting: a loop that serves several bridges without lockstep moves time on for it.
POLLING = "polling"
_STALL_WARNING = 30.0  # wall seconds a lockstep engine waits on a busy mission before saying so
_CLOSED_GRACE = 2.0  # wall seconds a lockstep engine waits for an aborted mission to unwind
#: Calls that do not wait served in one engine period before the loop steps on (lockstep, simulated clock).
CALLS_PER_TICK = 10
#: Engine seconds a mission may poll without waiting while no belief changes before it is reported.
POLLING_REPORT = 30.0


class MissionStalled(RuntimeError):
    """Raised in a Python mission that polls a world nothing will change: a request of it was refused and none of
    its behaviors runs (the reason says which request, and why it was refused)."""


class MissionPreempted(Exception):
    """Raised in a Python mission's thread when a safety rule hands the mission over to ``function``."""

    def __init__(self, function: Callable[[], Any], message: str) -> None:
        super().__init__(message)
        self.function = function


class _Request:
    __slots__ = ("function", "waits", "done", "value", "error", "thread")

    def __init__(self, function: Callable, waits: bool) -> None:
        self.thread = threading.get_ident()  # the mission's thread that asks
        self.function = function
        self.waits = waits
        self.done = threading.Event()
        self.value: Any = None
        self.error: BaseException | None = None


class _Mission:
    """Whether the mission runs, waits or is done: one for every engine a program drives (a script flying a
    fleet is one mission whichever drone it waits on). It runs while one of its threads runs: the mission thread,
    or a thread of the script's own (:meth:`MissionBridge.thread_started`) that is not waiting on an engine or
    joining another."""

    __slots__ = ("cond", "done", "joiners", "polls", "polls_at", "running")

    def __init__(self) -> None:
        self.cond = threading.Condition()
        self.done = True
        self.running = 0  # the mission's threads running Python code now
        self.joiners: dict[Any, int] = {}  # each of the script's own threads not ended -> its threads joining it
        self.polls, self.polls_at = 0, -1.0  # calls that did not wait, served at engine time polls_at

    @property
    def state(self) -> str:
        return DONE if self.done else RUNNING if self.running > 0 else PARKED


class MissionBridge:
    """Queues the mission thread's calls for the engine thread; tracks whether the mission runs or waits."""

    def __init__(self, now: Callable[[], float] | None = None, world_version: Callable[[], int] | None = None,
                 report: Callable[[str], None] | None = None, stalled: Callable[[], str | None] | None = None
                 ) -> None:
        """``now``, ``world_version`` (changes whenever a belief does) and ``report`` let the bridge tell of a
        mission that polls a world that does not change; ``stalled`` says why nothing will change it (a request
        of the mission was refused and none of its behaviors runs), and such a mission is then ended with that
        reason (:class:`MissionStalled`) instead of polling until the time limit."""
        self._queue: queue.SimpleQueue[_Request] = queue.SimpleQueue()
        #: What each call is served within (the engine's period guard: Ctrl-C waits for the call's end).
        self.guard: Callable[[], contextlib.AbstractContextManager[Any]] = contextlib.nullcontext
        self._mission = _Mission()
        self._pending: set[_Request] = set()
        self._closed = False
        self._closed_at = 0.0
        self._held = False
        self._now, self._world_version, self._report = now, world_version, report
        self._stalled = stalled
        self._stall: MissionStalled | None = None  # raised in the mission at its next call that does not wait
        self._stalled_threads: set[int] = set()  # the mission's threads it was raised in (once in each)
        self._polls = 0  # calls without a wait since the last wait or change of the world
        self._poll_since: float | None = None
        self._poll_version: int | None = None
        self._poll_reported = False
        self.preempted: BaseException | None = None
        #: Journals the mission's API calls and replays them on a resume (``missions/replay.py``); None: neither.
        self.recorder: Any = None

    @property
    def _cond(self) -> threading.Condition:
        return self._mission.cond

    @property
    def _state(self) -> str:
        return self._mission.state

    def _running(self, change: int) -> None:
        """``change`` threads of the mission start or stop running Python code (call with the lock held)."""
        self._mission.running = max(0, self._mission.running + change)
        self._cond.notify_all()

    def thread_started(self, thread: Any) -> None:
        """A thread of the script's own starts: the mission runs while it does."""
        with self._cond:
            self._mission.joiners[thread] = 0
            self._running(+1)

    def thread_ended(self, thread: Any) -> None:
        """A thread of the script's own ends; the threads of the mission joining it run again from this moment,
        not from when they wake (late on a loaded machine: no engine step falls in between)."""
        with self._cond:
            self._running(self._mission.joiners.pop(thread, 0) - 1)

    def joining(self, thread: Any) -> bool:
        """A thread of the mission starts waiting for ``thread`` to end (``join``): it no longer runs until
        ``thread`` ends. False when ``thread`` is no thread of the mission still running: the joiner runs on."""
        with self._cond:
            if thread not in self._mission.joiners:
                return False
            self._mission.joiners[thread] += 1
            self._running(-1)
            return True

    def joined(self, thread: Any) -> None:
        """The wait :meth:`joining` began is over. When ``thread`` ended, its end made the joiner run already;
        otherwise (a ``join`` with a timeout that passed) the joiner runs again now."""
        with self._cond:
            if self._mission.joiners.get(thread, 0) > 0:
                self._mission.joiners[thread] -= 1
                self._running(+1)

    def share_mission(self, others: Iterable[MissionBridge]) -> None:
        """The bridges of other engines the same program drives see this one's mission: it runs, waits or is
        done once, whichever engine it calls (a lockstep loop over them waits for it as for one)."""
        for other in others:
            other._mission = self._mission

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
        if self.preempted is not None:  # a safety rule handed the mission over to one of its functions
            preempted, self.preempted = self.preempted, None
            raise preempted
        with self._cond:
            self._queue.put(request)
            self._cond.notify_all()
        while not request.done.wait(0.5):
            if self._closed:
                raise MissionAborted("the engine has stopped")
        if request.error is not None:
            raise request.error
        return request.value

    def preempt(self, preempted: BaseException) -> None:
        """The mission thread raises ``preempted`` from the call it waits in, or its next call (a safety rule's
        contingency ``call FUNCTION``, engine/safety)."""
        with self._cond:
            self.preempted = preempted
            if self._pending:  # the woken mission runs on: a lockstep loop waits for it, as after close()
                self._running(len(self._pending))
            for request in self._pending:
                request.error, self.preempted = preempted, None
                request.done.set()
            self._pending.clear()
            self._cond.notify_all()

    def mission_started(self) -> None:
        with self._cond:
            self._mission.done, self._mission.running = False, 1
            self._closed = False

    def mission_finished(self) -> None:
        with self._cond:
            self._mission.done = True
            self._cond.notify_all()

    # -- the engine's side ---------------------------------------------------------------
    @property
    def state(self) -> str:
        mission = self._mission
        state = mission.state
        if state == RUNNING and mission.polls >= CALLS_PER_TICK and self._now is not None \
                and mission.polls_at == self._now():
            return POLLING
        return state

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
        if until_wall is None:
            if not lockstep:
                if self._held or self._queue.empty():
                    return  # nothing to serve now and nothing to wait for (a fleet's period asks every drone's mission)
            elif self._state == DONE and self._queue.empty():
                return  # no mission, nothing queued: nothing to wait for (a call queued now is served next period)
        warned_at = time.monotonic() + _STALL_WARNING
        served = 0
        while True:
            request = None
            if not self._held and not self._queue.empty():
                with contextlib.suppress(queue.Empty):
                    request = self._queue.get_nowait()
            if request is not None:
                with self.guard():
                    self._execute(request)
                if not request.waits:
                    served += 1
                    self._polled()
                    if lockstep and served >= CALLS_PER_TICK:
                        return  # the engine steps on: polling lets time move
                elif request.done.is_set():  # a wait that ended at once (a refused request): time moves on first
                    if self._now is not None:
                        self._mission.polls, self._mission.polls_at = CALLS_PER_TICK, self._now()
                    if lockstep:
                        return
                continue
            with self._cond:
                # in lockstep the mission's own code runs to its next call even while held (a wait that ended
                # during a pause), so what it does never depends on thread timing; held, that call waits queued
                if (lockstep and self._state == RUNNING and (not self._held or self._queue.empty())
                        and not (self._closed and time.monotonic() > self._closed_at + _CLOSED_GRACE)):
                    self._cond.wait(0.05)
                    if time.monotonic() > warned_at:
                        logger.warning("the mission has been busy for %.0f s of wall time without calling the "
                                       "engine; simulated time waits for it", _STALL_WARNING)
                        warned_at = time.monotonic() + _STALL_WARNING
                    continue
                if until_wall is None or time.monotonic() >= until_wall:
                    return
                self._cond.wait(min(0.05, max(0.0, until_wall - time.monotonic())))

    def _polled(self) -> None:
        """Count a call that did not wait; report a long stretch of them while no belief changes."""
        if self._now is None:
            return
        now = self._now()
        mission = self._mission
        mission.polls, mission.polls_at = (mission.polls + 1, now) if mission.polls_at == now else (1, now)
        version = self._world_version() if self._world_version is not None else None
        if self._poll_since is None or version != self._poll_version:
            self._polls, self._poll_since, self._poll_version, self._poll_reported = 0, now, version, False
        self._polls += 1
        if not self._poll_reported and now - self._poll_since >= POLLING_REPORT:
            self._poll_reported = True
            message = (f"the mission has polled the engine {self._polls} times in {now - self._poll_since:.0f} s "
                       f"without waiting, and no belief has changed: it waits for something nothing is doing "
                       f"(start a behavior, or wait with a timeout)")
            logger.warning(message)
            if self._report is not None:
                self._report(message)
            why = self._stalled() if self._stalled is not None else None
            if why is not None:
                self._stall = MissionStalled(f"the mission polls for something nothing is doing: {why}")

    def _execute(self, request: _Request) -> None:
        if request.waits:
            self._poll_since = None  # a wait ends a stretch of polling
        if not request.waits:
            if self._stall is not None and request.thread not in self._stalled_threads:
                self._stalled_threads.add(request.thread)  # each thread of the mission that polls on hears it once
                request.error = self._stall
                request.done.set()
                return
            try:
                request.value = request.function()
            except KeyboardInterrupt:  # Ctrl-C or SIGTERM reached the loop's thread: it is the loop's to handle
                request.error = MissionAborted("interrupted by the operator")
                request.done.set()
                raise
            except BaseException as exc:  # handed to the mission thread, which raises it
                request.error = exc
            request.done.set()
            return
        with self._cond:
            self._running(-1)
            self._pending.add(request)

        def resolve(value: Any) -> None:
            with self._cond:
                if request not in self._pending:
                    return
                self._pending.discard(request)
                request.value = value
                self._running(+1)
                request.done.set()

        try:
            request.function(resolve)
        except BaseException as exc:
            interrupted = isinstance(exc, KeyboardInterrupt)  # the loop's to handle: the mission is aborted
            with self._cond:
                self._pending.discard(request)
                request.error = MissionAborted("interrupted by the operator") if interrupted else exc
                self._running(+1)
                request.done.set()
            if interrupted:
                raise

    def close(self) -> None:
        """Abort every waiting call: the mission thread raises :class:`MissionAborted`."""
        with self._cond:
            self._closed = True
            self._closed_at = time.monotonic()
            if self._pending:  # the woken mission now runs to its end: a lockstep loop waits for it (a moment)
                self._running(len(self._pending))
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
