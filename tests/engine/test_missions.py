"""Missions on the default catalog and library: the low-battery reaction, and Appendix A's activation conditions."""

import aeroexec.engine.api as api
import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome


def run(mission, battery=100.0, max_time=300.0):
    world = default_world()
    engine = Engine(SimulatedDrone(world, config=SimConfig(initial_battery_percent=battery)), obstacles=world)
    try:
        engine.run(mission, max_time=max_time)
        engine.run_until(lambda: not engine.coordinator.is_active("LAND"), 60.0)  # as aeroexec run does
    finally:
        engine.stop()
    return engine


def test_land_preempts_the_mission_when_the_battery_falls_below_10():
    results = []

    def mission():
        results.append(api.execute_behavior("TAKE_OFF"))
        for _ in range(10):  # a patrol that would need far more battery than there is
            results.append(api.execute_behavior("GO_TO_POINT", coordinates=[-5, -12, 2]))
            results.append(api.execute_behavior("GO_TO_POINT", coordinates=[8, -12, 2]))

    engine = run(mission, battery=10.6)
    assert results[0] == Outcome.GOAL_ACHIEVED
    assert Outcome.INTERRUPTED in results  # the GO_TO_POINT the mission was waiting on
    interrupted = engine.log.events(kind="INTERRUPTED", behavior="GO_TO_POINT")[0]
    assert interrupted.detail == "stopped for LAND (reactive)"
    assert engine.log.events(kind="reactive", behavior="LAND")
    assert engine.log.events(kind="GOAL_ACHIEVED", behavior="LAND")
    assert results[results.index(Outcome.INTERRUPTED) + 1:] and all(
        r == Outcome.FAILED_PRECONDITIONS for r in results[results.index(Outcome.INTERRUPTED) + 1:])
    refused = engine.log.events(kind="failed_preconditions", behavior="GO_TO_POINT")[0].detail
    assert refused.endswith("belong(?x1, [moving, hovering]) does not hold with ?x1 = landing")
    assert engine.drone.telemetry().altitude == pytest.approx(0.0, abs=0.01)
    assert engine.drone.telemetry().battery_percent > 7.0  # landed before the drone's own failsafe


def test_recurrent_behaviors_start_when_their_activation_conditions_hold():
    seen = {}

    def mission():
        api.execute_behavior("TAKE_OFF")
        api.activate_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS", activation_delay=3.0)
        api.activate_behavior("PAY_ATTENTION_TO_COLORS", activation_distance=((8, -8, 2), 1.0))
        seen["start"] = api.now()
        api.execute_behavior("GO_TO_POINT", coordinates=[8, -8, 2])
        seen["arrived"] = api.now()
        api.wait(1.0)

    engine = run(mission)
    activated = {e.behavior: e for e in engine.log.events(kind="activated")}
    assert activated["PAY_ATTENTION_TO_VISUAL_MARKERS"].data["waiting"] == "starts 3 s after the request"
    started = {e.behavior: e.time for e in engine.log.events(kind="started")}
    capabilities = {e.detail: e.time for e in engine.log.events(kind="capability_started")}
    assert started["PAY_ATTENTION_TO_VISUAL_MARKERS"] == pytest.approx(seen["start"] + 3.0, abs=0.06)
    assert capabilities["VISUAL_MARKERS_RECOGNITION"] == started["PAY_ATTENTION_TO_VISUAL_MARKERS"]
    assert seen["start"] + 2.0 < started["PAY_ATTENTION_TO_COLORS"] <= seen["arrived"]  # within 1 m of the point
    assert capabilities["COLOR_RECOGNITION"] == started["PAY_ATTENTION_TO_COLORS"]
