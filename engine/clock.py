"""Engine clocks: simulated time for the built-in simulator, wall time for real drones.

The engine loop asks its clock for the time and to wait until the next tick.
A :class:`SimulatedClock` only moves when the loop advances it, so a simulated
mission runs as fast as the CPU allows (or ``speed`` times real time) and two
runs with the same inputs see the same times. A :class:`WallClock` follows
``time.monotonic``.
"""

from __future__ import annotations

import abc
import threading
import time


class Clock(abc.ABC):
    """Time in seconds since the clock started; ``sleep_until`` waits for the next tick."""

    @abc.abstractmethod
    def now(self) -> float: ...

    @abc.abstractmethod
    def sleep_until(self, deadline: float, stop: threading.Event | None = None) -> None:
        """Wait until ``now() >= deadline`` or ``stop`` is set."""

    def __call__(self) -> float:
        return self.now()


class SimulatedClock(Clock):
    """Time that jumps to each deadline; with ``speed`` it is paced to that many times real time.

    ``speed=None`` (the default) runs as fast as possible.
    """

    def __init__(self, start: float = 0.0, speed: float | None = None) -> None:
        if speed is not None and speed <= 0:
            raise ValueError(f"the simulation speed must be positive, not {speed}")
        self._now = float(start)
        self.speed = speed
        self._origin_wall = time.monotonic()
        self._origin_sim = self._now

    def now(self) -> float:
        return self._now

    def sleep_until(self, deadline: float, stop: threading.Event | None = None) -> None:
        if deadline <= self._now:
            return
        if self.speed is not None:
            wall_deadline = self._origin_wall + (deadline - self._origin_sim) / self.speed
            delay = wall_deadline - time.monotonic()
            if delay > 0:
                if stop is not None:
                    stop.wait(delay)
                else:
                    time.sleep(delay)
        self._now = deadline

    def pace_from_now(self) -> None:
        """Count the pacing from now: the time now is the wall time now (a flight whose set-up took a while does not
        run unpaced until it has caught up)."""
        self._origin_wall = time.monotonic()
        self._origin_sim = self._now

    def advance(self, seconds: float) -> None:
        """Move time forward by ``seconds`` at once (tests)."""
        if seconds < 0:
            raise ValueError("a clock cannot go back")
        self._now += seconds


class WallClock(Clock):
    """Real time, from ``time.monotonic``, starting at ``start`` (zero; a resumed run goes on from its time)."""

    def __init__(self, start: float = 0.0) -> None:
        self._origin = time.monotonic() - float(start)

    def now(self) -> float:
        return time.monotonic() - self._origin

    def sleep_until(self, deadline: float, stop: threading.Event | None = None) -> None:
        delay = deadline - self.now()
        if delay <= 0:
            return
        if stop is not None:
            stop.wait(delay)
        else:
            time.sleep(delay)
