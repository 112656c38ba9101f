"""Belief updaters: periods on the engine clock, publishing scopes, failures contained."""

import pytest
from aeroexec.beliefs import BeliefMemory, BeliefUpdater, FunctionUpdater, publish


def test_publish_replaces_a_scope_and_reports_only_real_changes():
    memory = BeliefMemory()
    heard = []
    memory.subscribe(lambda change: heard.append(str(change)))
    memory.add("object(marker_1, aruco)")
    assert publish(memory, "visible(?)", ["visible(marker_1)", "visible(marker_2)"]) == (2, 0)
    heard.clear()
    assert publish(memory, "visible(?)", ["visible(marker_2)"]) == (0, 1)
    assert heard == ["-visible(marker_1) (remove)"]
    assert memory.holds("object(marker_1, aruco)")  # only the scope changes
    assert [str(b) for b in memory.matching("visible(?X)")] == ["visible(marker_2)"]
    with pytest.raises(ValueError, match="outside the scope"):
        publish(memory, "visible(?)", ["seen(marker_2)"])


def test_updaters_run_at_their_period_on_the_given_clock():
    memory = BeliefMemory()
    calls = []

    def observe(m, now):
        calls.append(now)
        m.add(f"clock(self, {now})")

    updater = FunctionUpdater("clock", observe, period=0.5)
    for tick in range(0, 21):
        updater.tick(memory, tick * 0.1)
    assert calls == pytest.approx([0.0, 0.5, 1.0, 1.5, 2.0])
    assert memory.query("clock(self, ?T)") == {"?T": 2.0}


def test_a_failing_updater_is_logged_and_the_engine_goes_on(caplog):
    class Broken(BeliefUpdater):
        def update(self, memory, now):
            raise RuntimeError("sensor unplugged")

    updater = Broken("broken", period=0.0)
    updater.tick(BeliefMemory(), 0.0)
    updater.tick(BeliefMemory(), 0.1)
    assert caplog.text.count("belief updater broken failed") == 2

