"""PAY_ATTENTION_TO_*: what the simulated camera sees becomes beliefs while the behavior is active."""

import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine


@pytest.fixture
def engine():
    world = default_world()
    eng = Engine(SimulatedDrone(world), obstacles=world)
    eng.drone.takeoff(2.0)
    eng.run_until(lambda: eng.memory.holds("flight_state(self, hovering)"), 30)
    yield eng
    eng.stop()


def fly_to(engine, point, yaw):
    engine.drone.goto(point, yaw=yaw)
    engine.run_until(lambda: engine.drone.telemetry().speed < 0.05
                     and abs(engine.drone.telemetry().yaw - yaw) < 1.0, 30)
    engine.step(0.5)


def test_markers_in_view_become_beliefs_and_visibility_follows_the_camera(engine):
    fly_to(engine, (8.0, 0.0, 2.0), yaw=90)  # facing north: the tower's south face and marker 1
    assert not engine.memory.holds("code(?M, 1)")  # nobody is paying attention yet
    assert engine.coordinator.activate("PAY_ATTENTION_TO_VISUAL_MARKERS").accepted
    assert "VISUAL_MARKERS_RECOGNITION" in engine.resources.running()
    engine.step(0.5)
    assert engine.memory.holds("object(marker_1, aruco), object(marker_1, marker), code(marker_1, 1)")
    assert engine.memory.holds("visible(marker_1)")
    found = engine.memory.query("position(marker_1, (?X, ?Y, ?Z))")
    assert found == {"?X": 8.0, "?Y": 6.45, "?Z": 2.0}
    assert engine.memory.holds("object(?M, marker), code(?M, 1)")  # the paper's query form
    fly_to(engine, (8.0, 0.0, 2.0), yaw=-90)  # turn away
    assert not engine.memory.holds("visible(marker_1)")  # null persistence
    assert engine.memory.holds("code(marker_1, 1), position(marker_1, ?P)")  # the rest is remembered


def test_nothing_is_recognized_after_the_behavior_is_inhibited(engine):
    engine.coordinator.activate("PAY_ATTENTION_TO_VISUAL_MARKERS")
    engine.coordinator.inhibit("PAY_ATTENTION_TO_VISUAL_MARKERS")
    engine.step(3.0)  # past the capability's grace period
    assert "VISUAL_MARKERS_RECOGNITION" not in engine.resources.running()
    fly_to(engine, (8.0, 0.0, 2.0), yaw=90)
    assert not engine.memory.holds("code(?M, 1)")


def test_colors_and_shapes(engine):
    engine.coordinator.activate("PAY_ATTENTION_TO_COLORS")
    engine.coordinator.activate("PAY_ATTENTION_TO_SHAPES")
    fly_to(engine, (0.0, 0.0, 2.0), yaw=0)  # facing east: the red box at (4, 2) on the ground
    assert engine.memory.holds("color(red_box, red), visible(red_box)")
    assert engine.memory.holds("shape(red_box, box), object(red_box, box)")
    assert engine.memory.query("color(?O, blue)") is None  # the blue ball is behind the drone


def test_wait_for_a_duration_and_until_a_marker_is_observed(engine):
    assert engine.coordinator.activate("WAIT", {"DURATION": 2.0}).accepted
    start = engine.now()
    engine.run_until(lambda: not engine.coordinator.is_active("WAIT"), 10)
    assert engine.log.events(kind="GOAL_ACHIEVED", behavior="WAIT")
    assert engine.now() - start == pytest.approx(2.0, abs=0.06)
    engine.coordinator.activate("PAY_ATTENTION_TO_VISUAL_MARKERS")
    assert engine.coordinator.activate("WAIT", {"UNTIL_OBSERVED_VISUAL_MARKER": 1}).accepted
    engine.step(3.0)
    assert engine.coordinator.is_active("WAIT")  # marker 1 is not in view from home
    engine.drone.goto((8.0, 0.0, 2.0), yaw=90)  # now it comes into view
    assert engine.run_until(lambda: not engine.coordinator.is_active("WAIT"), 30)
    assert len(engine.log.events(kind="GOAL_ACHIEVED", behavior="WAIT")) == 2
    assert engine.memory.holds("code(?M, 1), visible(?M)")
