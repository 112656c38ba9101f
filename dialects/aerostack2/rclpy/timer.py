"""``rclpy.timer`` as a mission sees it: a node's :class:`Timer`, whose callback the executor spinning the node
calls every period of the engine's clock (rcl's timer, ``rcl_timer_call``: called when due, the next call a period
after the one due; periods a long callback overran are skipped, not made up)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from aeroexec.dialects.aerostack2.rclpy.clock import Clock, now_ns


class Timer:
    """``node.create_timer(period_sec, callback)``: ``cancel()``, ``reset()``, ``is_canceled()``, ``is_ready()``,
    ``time_until_next_call()``, ``time_since_last_call()``, ``timer_period_ns``, ``destroy()``."""

    def __init__(self, callback: Callable[[], Any] | None, period_ns: int, clock: Clock, autostart: bool = True,
                 owner: Any = None) -> None:
        if period_ns < 0:
            raise ValueError(f"a timer's period cannot be negative ({period_ns / 1e9:g} s)")
        self.callback, self._period, self._clock, self._owner = callback, int(period_ns), clock, owner
        now = now_ns()
        self._last = now
        self._next: int | None = now + self._period if autostart else None

    @property
    def clock(self) -> Clock:
        return self._clock

    @property
    def timer_period_ns(self) -> int:
        return self._period

    @timer_period_ns.setter
    def timer_period_ns(self, value: int) -> None:
        self._period = int(value)
        if self._next is not None:
            self._next = self._last + self._period

    def is_canceled(self) -> bool:
        return self._next is None

    def cancel(self) -> None:
        self._next = None

    def reset(self) -> None:
        self._last = now_ns()
        self._next = self._last + self._period

    def is_ready(self) -> bool:
        return self._next is not None and self._next <= now_ns()

    def time_until_next_call(self) -> int | None:
        return None if self._next is None else self._next - now_ns()

    def time_since_last_call(self) -> int:
        return now_ns() - self._last

    def due(self) -> int | None:
        """When the timer is next due, in nanoseconds of the engine's clock (None: canceled)."""
        return self._next

    def call(self, now: int) -> None:
        """Called by an executor when the timer is due at ``now``: the next call is scheduled (as rcl's
        ``rcl_timer_call`` does, before the callback runs), then the callback runs."""
        if self._next is None:
            return
        self._last = now
        following = self._next + self._period  # a period after the call that was due, not after now
        if following < now:  # periods missed: the next call is the first period's end not before now
            following = now if self._period == 0 else \
                following + (1 + (now - following - 1) // self._period) * self._period
        self._next = following
        if self.callback is not None:
            self.callback()

    def destroy(self) -> None:
        self.cancel()
        if self._owner is not None and self in self._owner.timers:
            self._owner.timers.remove(self)

    def __enter__(self) -> Timer:
        return self

    def __exit__(self, *exc_info: Any) -> None:
        self.destroy()


__all__ = ["Timer"]
