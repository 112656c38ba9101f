"""Whole lines only on a shared text stream: what the mission prints and what the engine reports come from
different threads, and a line of one never breaks into a line of the other."""

from __future__ import annotations

import contextlib
import io
import sys
import threading
from collections.abc import Iterator

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import TextIO

class LineWriter(io.TextIOBase):
    """Buffers each thread's text until its newline, then writes the whole line(s) to ``target`` under a lock."""

    def __init__(self, target: TextIO) -> None:
        self.target = target
        self._lock = threading.Lock()
        self._partial: dict[int, str] = {}

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        with self._lock:
            key = threading.get_ident()
            head, newline, tail = (self._partial.pop(key, "") + text).rpartition("\n")
            if newline:
                self.target.write(head + newline)
                self.target.flush()
            if tail:
                self._partial[key] = tail
        return len(text)

    def flush(self) -> None:  # a partial line waits for its end, so that nothing cuts into it
        with self._lock:
            self.target.flush()

    def finish(self) -> None:
        """Write out the lines some thread left unterminated."""
        with self._lock:
            for text in self._partial.values():
                self.target.write(text + "\n")
            self._partial.clear()
            self.target.flush()

    def isatty(self) -> bool:
        return self.target.isatty()

    @property
    def encoding(self) -> str:  # type: ignore[override]
        return getattr(self.target, "encoding", "utf-8")


@contextlib.contextmanager
def whole_lines() -> Iterator[LineWriter]:
    """``sys.stdout`` as a :class:`LineWriter` for the duration of the block."""
    previous = sys.stdout
    writer = LineWriter(previous)
    sys.stdout = writer
    try:
        yield writer
    finally:
        sys.stdout = previous
        writer.finish()


def write_output(text: str, output: str | None, done: str) -> int:
    """A command's text to ``output`` (a file) or to standard output; says ``done`` on stderr once written. The
    exit status: 0, or 1 with the reason when the file cannot be written."""
    if not output:
        sys.stdout.write(text)
        return 0
    try:
        with open(output, "w", encoding="utf-8") as file:
            file.write(text)
    except OSError as error:
        print(f"{output}: cannot write it: {error.strerror or error}", file=sys.stderr)
        return 1
    print(f"{output}: {done}", file=sys.stderr)
    return 0
