"""Signals that end a flight as Ctrl-C does: SIGTERM (a service manager, ``kill``) and SIGHUP (the terminal
closed) raise :class:`Interrupted`, a KeyboardInterrupt, in the main thread, so the flight aborts, lands and
closes its log whatever ended it; a second one leaves the drone as it is, like a second Ctrl-C."""

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


def _raise(signum: int, _frame: object) -> None:
    raise Interrupted(signal.Signals(signum).name)


@contextlib.contextmanager
def ending_signals() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise :class:`Interrupted` in the main thread (elsewhere: nothing
    changes, signals only reach the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, _raise) for number in ENDING_SIGNALS}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


__all__ = ["ENDING_SIGNALS", "Interrupted", "ending_signals"]
