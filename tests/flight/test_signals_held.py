"""An ending signal waits for the end of the main thread's block (an engine period), never for another thread's."""

import os
import signal
import threading

import pytest
from aeroexec.flight.signals import Interrupted, ending_signals, interrupts_held


def test_a_signal_within_the_main_threads_block_is_raised_at_its_end():
    reached = []
    with ending_signals(), pytest.raises(Interrupted) as raised, interrupts_held():
        with interrupts_held():  # nested: the outer block's end raises it
            os.kill(os.getpid(), signal.SIGTERM)
            reached.append("inner end")
        reached.append("outer end")
    assert raised.value.signal_name == "SIGTERM"
    assert reached == ["inner end", "outer end"]


def test_another_threads_block_does_not_hold_the_main_threads_signal():
    inside, leave = threading.Event(), threading.Event()

    def period() -> None:
        with interrupts_held():
            inside.set()
            leave.wait(30)

    other = threading.Thread(target=period)
    with ending_signals():
        other.start()
        try:
            assert inside.wait(30)
            with pytest.raises(Interrupted):  # at once: the main thread is in no block
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(10_000):  # instructions for the handler to run between (it runs at the first)
                    pass
        finally:
            leave.set()
            other.join(30)
