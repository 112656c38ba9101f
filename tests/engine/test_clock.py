"""Engine clocks: simulated time moves only when the loop advances it."""

import threading
import time

import pytest
from aeroexec.beliefs import BeliefMemory
from aeroexec.engine.clock import SimulatedClock, WallClock


def test_simulated_time_jumps_to_each_deadline_without_waiting():
    clock = SimulatedClock()
    start = time.monotonic()
    for tick in range(1, 2001):
        clock.sleep_until(tick * 0.05)
    assert clock.now() == pytest.approx(100.0)
    assert time.monotonic() - start < 1.0  # 100 simulated seconds in well under one real one


def test_paced_simulated_time_follows_the_speed():
    clock = SimulatedClock(speed=10.0)
    start = time.monotonic()
    clock.sleep_until(1.0)
    assert 0.08 < time.monotonic() - start < 0.5


def test_a_stop_event_cuts_a_wall_wait_short():
    stop = threading.Event()
    stop.set()
    clock = WallClock()
    start = time.monotonic()
    clock.sleep_until(30.0, stop)
    assert time.monotonic() - start < 0.5


def test_the_belief_memory_can_run_on_the_simulated_clock():
    clock = SimulatedClock()
    memory = BeliefMemory(persistence={"visible": 1.0}, clock=clock)
    memory.add("visible(marker_1)")
    clock.advance(2.0)
    assert not memory.holds("visible(marker_1)")
    with pytest.raises(ValueError):
        SimulatedClock(speed=0)
