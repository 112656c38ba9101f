"""The planning worker: path planning, exploration planning and grid building run off the engine loop.

A behavior submits a job and polls it every tick; the loop never waits for a plan. The answer comes back through
the engine's clock: on a wall clock as soon as the worker has it; on a simulated clock at a defined time after the
request (``plan_time`` seconds of simulated time, however long the computation took), so a simulated run stays
deterministic. Should the worker still be computing then, the simulated clock does not move past that time until
the answer is there (:meth:`PlanningWorker.wait_due`, called by the loop between two ticks, as it waits for a Python
mission in lockstep), at most ``wait_limit`` seconds of wall time; past that the job fails. Jobs run one at a time in
the order they were submitted; a cancelled job that has not started never runs, and the answer of one cancelled
while it runs is dropped.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

PLAN_TIME = 0.5  # s of simulated time a plan takes on a simulated clock
WAIT_LIMIT = 60.0  # s of wall time the loop waits, on a simulated clock, for a plan that is due


class PlanJob:
    """One request to the worker: poll it with :meth:`ready`, then read :attr:`result` or :attr:`error`."""

    def __init__(self, name: str, function: Callable[[], Any], due: float | None, wait_limit: float) -> None:
        self.name = name
        self.due = due  # engine time the answer may be used from (None: as soon as it is computed)
        self.result: Any = None
        self.error = ""  # why the job gave no result
        self.cancelled = False
        self._function = function
        self._wait_limit = wait_limit
        self._finished = threading.Event()

    def ready(self, now: float) -> bool:
        """Whether the answer can be used at engine time ``now`` (see the module's docstring for the clocks)."""
        if self.cancelled:
            return False
        if self.due is None:
            return self._finished.is_set()
        if now < self.due - 1e-9:
            return False
        self.wait()  # the engine loop has waited already (wait_due); others may ask ahead of it
        return True

    def wait(self) -> None:
        """Wait for the answer, at most the wait limit; past it the job fails."""
        if not self._finished.wait(self._wait_limit) and not self.error:
            self.error = f"the planner gave no answer within {self._wait_limit:g} s"
            self.cancelled = True
            logger.warning("planning job %s: %s", self.name, self.error)

    def cancel(self) -> None:
        """Nobody wants the answer any more (the behavior that asked was stopped)."""
        self.cancelled = True

    @property
    def finished(self) -> bool:
        return self._finished.is_set()

    def run(self) -> None:
        if not self.cancelled:
            try:
                self.result = self._function()
            except Exception as exc:  # a planner bug ends the request that asked, not the worker
                logger.exception("planning job %s failed", self.name)
                self.error = f"the planner raised {type(exc).__name__}: {exc}"
        self._finished.set()


class PlanningWorker:
    """A background thread running planning jobs for one engine; ``clock`` is the engine's time."""

    def __init__(self, clock: Callable[[], float], simulated: bool, plan_time: float = PLAN_TIME,
                 wait_limit: float = WAIT_LIMIT) -> None:
        self._clock = clock
        self.simulated = simulated
        self.plan_time = plan_time
        self.wait_limit = wait_limit
        self._jobs: queue.SimpleQueue[PlanJob | None] = queue.SimpleQueue()
        self._waiting: list[PlanJob] = []  # submitted on a simulated clock, answer not yet due or not yet used
        self._thread: threading.Thread | None = None
        self._closed = False
        self._lock = threading.Lock()

    def submit(self, name: str, function: Callable[[], Any], plan_time: float | None = None) -> PlanJob:
        """Run ``function()`` on the worker; the answer is due ``plan_time`` (default :attr:`plan_time`) simulated
        seconds from now on a simulated clock."""
        delay = self.plan_time if plan_time is None else plan_time
        job = PlanJob(name, function, self._clock() + delay if self.simulated else None, self.wait_limit)
        with self._lock:
            if self._closed:
                job.error, job.cancelled = "the engine has stopped", True
                return job
            if self._thread is None:
                self._thread = threading.Thread(target=self._work, name="aeroexec-planning", daemon=True)
                self._thread.start()
            self._jobs.put(job)
            if job.due is not None:
                self._waiting.append(job)
        return job

    def wait_due(self, deadline: float) -> None:
        """Before a simulated clock moves to ``deadline``: wait for every answer due by then (the engine loop)."""
        if not self._waiting:
            return
        for job in [j for j in self._waiting if j.due is not None and j.due <= deadline + 1e-9]:
            if not job.cancelled:
                job.wait()
        self._waiting = [j for j in self._waiting if not j.cancelled and not (j.finished and j.due <= deadline)]

    def _work(self) -> None:
        while True:
            job = self._jobs.get()
            if job is None:
                return
            job.run()

    def shutdown(self, timeout: float = 0.5) -> None:
        """Stop taking jobs and let the thread end (never waits longer than ``timeout`` for a running job)."""
        with self._lock:
            self._closed = True
            thread, self._thread = self._thread, None
        if thread is not None:
            self._jobs.put(None)
            thread.join(timeout)
