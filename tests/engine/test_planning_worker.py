"""Planning never blocks the loop: grid searches run on the planning worker; GO_TO_POINT and
GENERATE_PATH_FREE_OF_OBSTACLES wait RUNNING for the answer, with their timeout counted, and can be stopped.

A planner held on an event stands for a search that takes forever."""

import math
import threading
import time

import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.engine.clock import WallClock
from aeroexec.engine.engine import Engine
from aeroexec.engine.execution.process import EngineSettings
from aeroexec.engine.planning.path_planner import PathPlanner
from aeroexec.engine.planning.worker import PlanningWorker

BEHIND_THE_TOWER = [12.0, 12.0, 2.0]  # no straight line from home: a grid search decides


@pytest.fixture
def held_planner(monkeypatch):
    """Searches on the planning worker wait for ``gate`` (set at the end of the test, so the worker ends)."""
    gate, entered = threading.Event(), threading.Event()
    original = PathPlanner.plan

    def plan(self, start, goal):
        if threading.current_thread().name == "aeroexec-planning":
            entered.set()
            gate.wait(30.0)
        return original(self, start, goal)

    monkeypatch.setattr(PathPlanner, "plan", plan)
    yield gate, entered
    gate.set()


def engine_for(drone=None, **extra):
    world = default_world()
    return Engine(drone or SimulatedDrone(world), obstacles=world, settings=EngineSettings(extra=extra))


def kinds(engine, behavior):
    return [e.kind for e in engine.log.events() if e.behavior == behavior]


def take_off(engine):
    assert engine.coordinator.activate("TAKE_OFF", {"ALTITUDE": 2.0}).accepted
    assert engine.run_until(lambda: not engine.coordinator.is_active("TAKE_OFF"), 30.0)
    assert kinds(engine, "TAKE_OFF")[-1] == "GOAL_ACHIEVED"


def test_with_the_planner_held_the_loop_steps_a_pause_is_served_and_a_low_battery_land_preempts(held_planner):
    gate, entered = held_planner
    drone = SimulatedDrone(default_world(), config=SimConfig(initial_battery_percent=15.0, battery_hover_minutes=2.0))
    engine = engine_for(drone, planning_time=600.0)  # the answer is due long after this test
    take_off(engine)
    assert engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": BEHIND_THE_TOWER}).accepted
    first = engine.coordinator.active()["GO_TO_POINT"].process
    began, where = engine.now(), drone.telemetry().position
    engine.step(1.0)
    assert entered.wait(10.0), "the search never reached the planner"
    assert engine.now() >= began + 1.0 - 1e-6  # the loop steps while the planner is held
    assert engine.coordinator.is_active("GO_TO_POINT")
    assert math.dist(where, drone.telemetry().position) < 0.3  # holding while the search runs

    paused = engine.supervisor.execute("pause")  # an operator command, served by the loop meanwhile
    assert paused.ok and "stopped GO_TO_POINT" in paused.message
    assert engine.coordinator.is_active("KEEP_HOVERING") and not engine.coordinator.is_active("GO_TO_POINT")
    assert first.request.cancelled  # halted cleanly: nobody waits for that search any more
    engine.step(0.5)
    assert engine.supervisor.execute("resume").ok
    assert engine.coordinator.is_active("GO_TO_POINT")  # asked again: a second search queued behind the held one

    assert engine.run_until(lambda: engine.coordinator.is_active("LAND"), 30.0)  # the battery runs down
    assert drone.telemetry().battery_percent < 10.0
    assert not engine.coordinator.is_active("GO_TO_POINT")
    assert kinds(engine, "GO_TO_POINT")[-1] == "INTERRUPTED"
    assert any(e.kind == "reactive" and e.behavior == "LAND" for e in engine.log.events())
    assert engine.run_until(lambda: not drone.telemetry().armed or not engine.coordinator.is_active("LAND"), 60.0)
    assert "GOAL_ACHIEVED" in kinds(engine, "LAND") and drone.telemetry().altitude < 0.2

    gate.set()  # the held searches end; their answers are dropped
    engine.step(1.0)
    assert not engine.coordinator.is_active("GO_TO_POINT")
    began = time.monotonic()
    engine.stop()
    assert time.monotonic() - began < 5.0


def test_a_go_to_point_waiting_for_its_plan_times_out(held_planner):
    engine = engine_for(planning_time=600.0)
    take_off(engine)
    asked = engine.now()
    assert engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": BEHIND_THE_TOWER}, timeout=2.0).accepted
    assert engine.run_until(lambda: not engine.coordinator.is_active("GO_TO_POINT"), 10.0)
    assert kinds(engine, "GO_TO_POINT")[-1] == "TIME_OUT"
    assert engine.now() - asked == pytest.approx(2.0, abs=0.11)
    engine.stop()


def test_a_stopped_go_to_point_drops_its_search_and_the_drone_stays(held_planner):
    gate, entered = held_planner
    engine = engine_for(planning_time=1.0)
    take_off(engine)
    where = engine.drone.telemetry().position
    assert engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": BEHIND_THE_TOWER}).accepted
    process = engine.coordinator.active()["GO_TO_POINT"].process
    engine.step(0.5)
    assert engine.coordinator.stop("GO_TO_POINT", "halted by the tree")
    assert kinds(engine, "GO_TO_POINT")[-1] == "INTERRUPTED" and process.request.cancelled
    gate.set()
    engine.step(3.0)  # past the answer's due time: nothing flies on it
    assert math.dist(where, engine.drone.telemetry().position) < 0.3
    engine.stop()


@pytest.mark.parametrize("planning_time", [0.5, 1.5])
def test_on_a_simulated_clock_a_plan_takes_the_defined_time_however_long_it_computes(planning_time):
    engine = engine_for(planning_time=planning_time)
    take_off(engine)
    asked = engine.now()
    assert engine.coordinator.activate("GENERATE_PATH_FREE_OF_OBSTACLES",
                                       {"DESTINATION": BEHIND_THE_TOWER}).accepted
    assert engine.coordinator.is_active("GENERATE_PATH_FREE_OF_OBSTACLES")  # RUNNING while it searches
    assert engine.run_until(lambda: not engine.coordinator.is_active("GENERATE_PATH_FREE_OF_OBSTACLES"), 10.0)
    ended = [e for e in engine.log.events() if e.behavior == "GENERATE_PATH_FREE_OF_OBSTACLES"][-1]
    assert ended.kind == "GOAL_ACHIEVED" and ended.data["result"][-1] == BEHIND_THE_TOWER
    assert ended.time - asked == pytest.approx(planning_time, abs=0.051)  # due time, then the next tick
    engine.stop()


def test_go_to_point_flies_around_the_tower_with_the_worker_plan():
    engine = engine_for()
    take_off(engine)
    assert engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": BEHIND_THE_TOWER}).accepted
    assert engine.run_until(lambda: not engine.coordinator.is_active("GO_TO_POINT"), 60.0)
    assert kinds(engine, "GO_TO_POINT")[-1] == "GOAL_ACHIEVED"
    assert math.dist(engine.drone.telemetry().position, BEHIND_THE_TOWER) < 0.5
    engine.stop()


def test_on_a_wall_clock_the_loop_keeps_its_rate_while_the_planner_is_held(held_planner):
    gate, entered = held_planner
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, clock=WallClock())
    ticks = []
    engine.tick_callbacks.append(lambda: ticks.append(engine.now()))
    engine.start()
    try:
        with engine._lock:
            assert engine.coordinator.activate("TAKE_OFF", {"ALTITUDE": 2.0}).accepted
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and kinds(engine, "TAKE_OFF")[-1:] != ["GOAL_ACHIEVED"]:
            time.sleep(0.05)
        with engine._lock:
            assert engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": BEHIND_THE_TOWER}).accepted
        assert entered.wait(10.0)
        before = len(ticks)
        time.sleep(1.0)
        assert len(ticks) - before >= 5  # 20 Hz asked; a loaded machine still ticks while the search is held
        with engine._lock:
            assert engine.coordinator.is_active("GO_TO_POINT")
            assert engine.coordinator.stop("GO_TO_POINT", "halted")
    finally:
        gate.set()
        engine.stop()


def test_the_worker_runs_jobs_in_order_and_a_cancelled_job_never_runs():
    now = [0.0]
    worker = PlanningWorker(lambda: now[0], simulated=True, plan_time=1.0)
    gate, ran = threading.Event(), []
    first = worker.submit("first", lambda: (gate.wait(10.0), ran.append("first")))
    second = worker.submit("second", lambda: ran.append("second"))
    third = worker.submit("third", lambda: ran.append("third") or 3)
    second.cancel()
    assert not third.ready(0.5)  # not due yet on the simulated clock
    gate.set()
    assert first.ready(1.0) and third.ready(1.0) and third.result == 3
    assert ran == ["first", "third"] and not second.ready(1.0)
    worker.shutdown()
    refused = worker.submit("late", lambda: 1)
    assert refused.cancelled and refused.error == "the engine has stopped"
