"""An abort just after take-off began: the take-off stopped near the ground lands by itself, and the end of the
run waits for that landing instead of refusing LAND ("the flight state is landing") and leaving the drone."""

from aeroexec.drones import LandedState
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.flight.ending import end_flight


def test_an_abort_during_take_off_lands_and_the_run_has_no_fault():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    engine.step(0.1)
    assert engine.coordinator.activate("TAKE_OFF", {"ALTITUDE": 3.0}).accepted
    engine.step(0.4)  # climbing, below a metre
    assert 0.05 < engine.drone.telemetry().altitude < 1.0
    result = engine.supervisor.execute("abort", "test")
    assert result.ok and "landing" in result.message
    assert end_flight(engine) == []
    assert engine.drone.telemetry().landed_state is LandedState.ON_GROUND and not engine.drone.telemetry().armed
    assert not engine.log.events(kind="failed_preconditions", behavior="LAND")
