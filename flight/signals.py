"""Signals that end a flight as Ctrl-C does: SIGTERM (a service manager, ``kill``) and SIGHUP (the terminal
closed) raise :class:`Interrupted`, a KeyboardInterrupt, in the main thread, so the flight aborts, lands and
closes its log whatever ended it; a second one leaves the drone as it is, like a second Ctrl-C.

Within :func:`interrupts_held` (an engine period, the outputs closing) such a signal, and Ctrl-C, waits for the
block's end: a period is never cut in two, so the event log and the journal never keep one half of it each (a
commit interrupted half-way was rolled back, and its records lost to the journal). A second signal while one
waits raises that one at once (the operator insists)."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

#: The signals that end a flight like Ctrl-C (SIGINT raises KeyboardInterrupt by itself).
ENDING_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


class Interrupted(KeyboardInterrupt):
    """A signal asked the process to end; ``signal_name`` says which (``SIGTERM``)."""

    def __init__(self, signal_name: str) -> None:
        super().__init__(signal_name)
        self.signal_name = signal_name


class _Held(threading.local):
    depth = 0
    waiting: Interrupted | None = None


_held = _Held()


def _raise(signum: int, _frame: object) -> None:
    interrupt = Interrupted("Ctrl-C" if signum == signal.SIGINT else signal.Signals(signum).name)
    if _held.depth and _held.waiting is None:
        _held.waiting = interrupt  # raised when the block ends
        return
    if _held.waiting is not None:  # a second one while the first waits: the first, at once
        interrupt, _held.waiting = _held.waiting, None
    raise interrupt


class _InterruptsHeld:
    """:func:`interrupts_held`'s block: a class rather than a generator, entered once per engine period of every
    drone (a generator-based context manager costs several times as much to enter and leave), and one object for
    every block: it keeps nothing, the depth is the thread's own (``_held``). Any thread counts its blocks, but only
    the main thread's count holds a signal back: Python runs signal handlers in the main thread, so the handler
    reads the main thread's depth, and only the main thread has one waiting."""

    __slots__ = ()

    def __enter__(self) -> None:
        _held.depth += 1

    def __exit__(self, *_: object) -> None:
        held = _held
        held.depth -= 1
        if not held.depth and held.waiting is not None:
            interrupt, held.waiting = held.waiting, None
            raise interrupt


_HOLD = _InterruptsHeld()


def interrupts_held() -> contextlib.AbstractContextManager[None]:
    """Within the block (in the main thread), an ending signal or Ctrl-C is raised at the block's end, not within
    it; a second one is raised at once."""
    return _HOLD


@contextlib.contextmanager
def ending_signals() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise :class:`Interrupted` in the main thread, and so does Ctrl-C
    (``signal_name`` "Ctrl-C"), held within :func:`interrupts_held` (elsewhere: nothing changes, signals only
    reach the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, _raise) for number in (*ENDING_SIGNALS, signal.SIGINT)}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


__all__ = ["ENDING_SIGNALS", "Interrupted", "ending_signals", "interrupts_held"]
