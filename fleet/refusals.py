"""What a fleet node refuses, counted rather than repeated: the first refusal of each sender and reason is logged at
once, the rest are counted and logged as one line per sender and reason per interval ("refused 12,480 messages
from d9 in the last 10 s: ..."). Thread-safe: Zenoh's threads and the engines' report here.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

logger = logging.getLogger(__name__)

INTERVAL = 10.0  # wall seconds between two lines about the same sender and reason
MAX_KINDS = 10_000  # (sender, reason) pairs remembered; beyond, the oldest are forgotten (and logged again)


@dataclass
class _Count:
    what: str  # "message" or "belief"
    example: str
    since: float  # when the counting began
    count: int = 0


class Refusals:
    """The refusals of fleet ``fleet``'s node; ``clock`` is wall time (seconds)."""

    def __init__(self, fleet: str, interval: float = INTERVAL, clock: Callable[[], float] = time.monotonic) -> None:
        self.fleet, self.interval, self.clock = fleet, interval, clock
        self.total = 0
        self._counts: dict[tuple[str, str], _Count] = {}
        self._lock = threading.Lock()
        self._next_flush = 0.0

    def refuse(self, sender: str, reason: str, example: str = "", what: str = "message") -> bool:
        """Count one refusal; True (and one log line now) when ``sender`` had not been refused for ``reason``."""
        now = self.clock()
        with self._lock:
            self.total += 1
            count = self._counts.get((sender, reason))
            if count is not None:
                count.count += 1
                count.example = example or count.example
                return False
            if len(self._counts) >= MAX_KINDS:
                self._counts.pop(next(iter(self._counts)))
            self._counts[(sender, reason)] = _Count(what, example, now)
        logger.warning("fleet %s: refused a %s from %s: %s%s; more of the same are counted, one line every %g s",
                       self.fleet, what, sender, reason, f" ({_short(example)})" if example else "", self.interval)
        return True

    def flush(self, final: bool = False) -> None:
        """Log what was counted since the last line of each sender and reason, once ``interval`` has passed since
        that line (``final``: now, whatever the time)."""
        now = self.clock()
        if not final and now < self._next_flush:
            return
        self._next_flush = now + min(1.0, self.interval)
        lines = []
        with self._lock:
            for (sender, reason), count in self._counts.items():
                if count.count and (final or now - count.since >= self.interval):
                    lines.append((count.count, count.what, sender, now - count.since, reason, count.example))
                    count.count, count.since = 0, now
        for n, what, sender, seconds, reason, example in lines:
            logger.warning("fleet %s: refused %s more %s%s from %s in the last %.0f s: %s%s", self.fleet, f"{n:,}",
                           what, "" if n == 1 else "s", sender, seconds, reason,
                           f" (last: {_short(example)})" if example else "")


def _short(text: str, limit: int = 120) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[:limit - 1] + "…"
