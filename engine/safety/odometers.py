"""The odometers the safety monitors schedule by: for each drone whose position is believed (``position(self,
P)``, a fleet mate's ``position(dN, P)``), the path its believed position has travelled along each axis,
horizontally and in 3-D, and the rules waiting for a reading of one of them.

A value computed from a position cannot move farther than the position did, so a rule whose comparison is ``b``
away from flipping, at ``k`` per meter, need not be checked before the odometer has run ``b / k`` more meters
(:mod:`aeroexec.engine.safety.schedule`). The readings follow the beliefs themselves, as the rules read them.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from typing import Any

from aeroexec.engine.safety.schedule import AXES

_INDEX = {axis: i for i, axis in enumerate(AXES)}
Point = tuple[float, float, float]


class Odometers:
    """Follows drones' believed positions; ``wake(rule, generation)`` is called when a reading a rule waits for is
    reached, ``live(rule, generation)`` says whether such a wait still stands (a later check replaces it)."""

    def __init__(self, wake: Callable[[int, int], None], live: Callable[[int, int], bool]) -> None:
        self._wake, self._live = wake, live
        self._last: dict[Any, Point] = {}
        self._previous: dict[Any, Any] = {}  # who -> its point before the last move
        self._moved_at: dict[Any, float] = {}  # who -> when it last moved
        self._readings: dict[Any, list[float]] = {}  # who -> the five readings, in AXES' order
        self._heaps: dict[tuple, list[tuple[float, int, int]]] = {}  # (who, axis) -> (reading, generation, rule)
        self._watched: dict[Any, list[tuple[int, list]]] = {}  # who -> (axis index, heap) of the waits on it
        # who -> at most the path left before a wait on it is reached: no reading grows more than the 3-D path, so
        # a move shorter than that reaches none, and its heaps are not looked at
        self._slack: dict[Any, float] = {}

    def moved(self, who: Any, point: Any, at: float) -> bool:
        """Follow ``who`` to ``point`` (believed at time ``at``); False when it was not followed before (it appears,
        or was no point)."""
        last = self._last.get(who)
        self._previous[who] = last
        self._moved_at[who] = at
        if last is None or type(point) is not tuple or len(point) != 3:
            return self._appeared(who, point)
        x, y, z = point
        if (type(x) is not float or type(y) is not float or type(z) is not float) and not _is_point(point):
            return self._appeared(who, point)  # (the telemetry's are floats)
        self._last[who] = point
        dx, dy, dz = x - last[0], y - last[1], z - last[2]
        readings = self._readings[who]
        h = math.sqrt(dx * dx + dy * dy)
        readings[0] += dx if dx >= 0.0 else -dx  # (abs(), called, costs more: this runs at every move)
        readings[1] += dy if dy >= 0.0 else -dy
        readings[2] += dz if dz >= 0.0 else -dz
        readings[3] += h
        step = math.sqrt(h * h + dz * dz)
        readings[4] += step
        slack = self._slack.get(who)
        if slack is not None:
            slack -= step
            self._slack[who] = slack if slack > 0.0 else self._reached(who, readings)
        return True

    def _reached(self, who: Any, readings: list[float]) -> float:
        """Wake the rules whose readings on ``who``'s odometers are reached; the path left before the next."""
        left = math.inf
        for axis, heap in self._watched.get(who, ()):
            reading = readings[axis]
            while heap and heap[0][0] <= reading:
                _, generation, index = heapq.heappop(heap)
                self._wake(index, generation)
            if heap and heap[0][0] - reading < left:
                left = heap[0][0] - reading
        return left

    def _appeared(self, who: Any, point: Any) -> bool:
        if not _is_point(point):
            self._last.pop(who, None)
            return False
        self._last[who] = point
        if who not in self._readings:
            self._readings[who] = [0.0, 0.0, 0.0, 0.0, 0.0]
        return False

    def forget(self, who: Any, at: float) -> None:
        """``who``'s position is no longer believed (its readings stay: they only grow)."""
        self._previous[who] = self._last.pop(who, None)
        self._moved_at[who] = at

    def where(self, who: Any, before: float | None = None) -> Point | None:
        """``who``'s believed position, as floats; with ``before``, the one believed just before that time (its
        position at the previous tick, when it moved at this one)."""
        point = self._last.get(who)
        if before is not None and self._moved_at.get(who, -math.inf) >= before:
            point = self._previous.get(who)
        return floats(point)

    def last(self, who: Any) -> Any:
        """``who``'s believed position as it was believed (a point, or None): :meth:`where` reads it as floats."""
        return self._last.get(who)

    def reading(self, key: tuple) -> float:
        """The reading of odometer ``key`` = (who, axis) now."""
        readings = self._readings.get(key[0])
        return 0.0 if readings is None else readings[_INDEX[key[1]]]

    def wake_at(self, key: tuple, reading: float, generation: int, index: int) -> None:
        """Wake rule ``index`` (its check ``generation``) when odometer ``key`` reaches ``reading``."""
        heap = self._heaps.get(key)
        if heap is None:
            heap = self._heaps[key] = []
            self._watched.setdefault(key[0], []).append((_INDEX[key[1]], heap))
        elif len(heap) > 64:  # stale waits pile up while a drone stands still: keep those still standing
            live = self._live
            heap[:] = [e for e in heap if live(e[2], e[1])]
            heapq.heapify(heap)
        heapq.heappush(heap, (reading, generation, index))
        left = reading - self.reading(key)
        if left < self._slack.get(key[0], math.inf):
            self._slack[key[0]] = left


def floats(point: Any) -> Point | None:
    """A believed point as floats; None when it is none."""
    return None if point is None or not _is_point(point) else (float(point[0]), float(point[1]), float(point[2]))


def _is_point(value: Any) -> bool:
    if not isinstance(value, tuple) or len(value) != 3:
        return False
    for v in value:
        kind = type(v)
        if kind is not float and kind is not int:
            return False
    return True


__all__ = ["Odometers", "floats"]
