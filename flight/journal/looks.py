"""A Python mission's calls that only look (a polling loop), journaled in runs: one ``looks`` row a run, not a row
a call."""

from __future__ import annotations

import json
import zlib


class LookRun:
    """A run of calls that only look (a polling loop), kept as one row: the distinct calls with their answers, and
    which one each call was (a byte each, compressed: a loop of two calls asked 10,000 times is a few bytes)."""

    def __init__(self, seq: int, first: int, after: int) -> None:
        self.seq, self.first, self.after = seq, first, after
        self.next = first  # the number of the call that would go on this run
        self.calls: dict[tuple, int] = {}
        self.sequence = bytearray()
        self.returned_at = 0.0
        self.dirty = False
        self._calls_text = ("", 0)  # the distinct calls as JSON, and how many they were then

    def add(self, number: int, after: int, key: tuple, time: float) -> bool:
        """Add call ``number`` (``key``: function, arguments, location, result), returned at ``time``; False when it
        cannot go on this run (it does not follow, it is on the other side of the stop, or 256 calls are known)."""
        if number != self.next or after != self.after:
            return False
        calls = self.calls
        index = calls.get(key)
        if index is None:
            if len(calls) >= 256:
                return False
            index = calls[key] = len(calls)
        self.sequence.append(index)
        self.next += 1
        self.returned_at, self.dirty = time, True
        return True

    def row(self, segment: int) -> tuple:
        """The run as the ``looks`` table keeps it (written again at every commit while the run goes on)."""
        self.dirty = False
        text, known = self._calls_text
        if known != len(self.calls):  # a call the run had not seen before
            calls = [[f, json.loads(a), loc, json.loads(r)] for f, a, loc, r in self.calls]
            text = json.dumps(calls, separators=(",", ":"))
            self._calls_text = (text, len(self.calls))
        return (self.seq, segment, self.first, len(self.sequence), text, zlib.compress(bytes(self.sequence)),
                round(self.returned_at, 3), self.after)


__all__ = ["LookRun"]
