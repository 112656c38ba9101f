"""The end of a flight (engine/supervision/flight_end.py), on simulated time: a drone left in the air lands, an
armed one on the ground is disarmed, and what went wrong (a refused landing, a refused disarm, a lost link)
comes back as the run's faults; a link that comes back within the grace time lets the drone land."""

from __future__ import annotations

import dataclasses

import pytest
from aeroexec.drones import LandedState
from aeroexec.drones.interface import CommandHandle, DroneEvent, Failure
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.engine import api
from aeroexec.engine.engine import Engine
from aeroexec.flight.ending import end_flight


class Drone(SimulatedDrone):
    """The simulated drone with a radio that can drop, and commands that can be refused."""

    def __init__(self, *args, refuse: tuple[str, ...] = (), **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.refuse = refuse
        self.link_down_until: float | None = None  # simulated time the link comes back (inf: never)
        self._extra: list[DroneEvent] = []

    def drop_link(self, seconds: float) -> None:
        t = super().telemetry()
        self.link_down_until = t.time + seconds
        self._extra.append(DroneEvent(t.time, "link_lost", "no telemetry",
                                      {"altitude": round(t.position[2], 2), "in_air": True}))

    def telemetry(self):
        t = super().telemetry()
        if self.link_down_until is not None:
            if t.time < self.link_down_until:
                return dataclasses.replace(t, link_ok=False)
            self.link_down_until = None
            self._extra.append(DroneEvent(t.time, "link_restored"))
        return t

    def events(self):
        out, self._extra = self._extra + super().events(), []
        return out

    def land(self):
        if "land" in self.refuse:
            return CommandHandle.failed("land", Failure.DENIED, "land denied: the pad is blocked")
        if self.link_down_until is not None:
            return CommandHandle.failed("land", Failure.LINK_LOST, "land failed: the link is down")
        return super().land()

    def disarm(self):
        if "disarm" in self.refuse:
            return CommandHandle.failed("disarm", Failure.DENIED, "disarm denied: the autopilot says no")
        return super().disarm()


def flown(drone: Drone, mission=None) -> Engine:
    """An engine that flew ``mission`` (default: take off to 3 m and stop there)."""
    world = default_world()
    engine = Engine(drone, obstacles=world)

    def take_off() -> None:
        api.execute_behavior("TAKE_OFF", altitude=3)

    engine.run(mission or take_off, max_time=120)
    return engine


@pytest.fixture
def stop():
    engines: list[Engine] = []
    yield engines.append
    for engine in engines:
        engine.stop()


def test_a_drone_left_in_the_air_lands_and_disarms_without_faults(stop):
    drone = Drone(default_world())
    engine = flown(drone)
    stop(engine)
    assert engine.drone.telemetry().landed_state != LandedState.ON_GROUND
    assert end_flight(engine) == []
    t = drone.telemetry()
    assert t.landed_state == LandedState.ON_GROUND and not t.armed
    assert engine.log.events(kind="landing")


def test_an_armed_drone_on_the_ground_is_disarmed_by_command(stop):
    drone = Drone(default_world(), config=SimConfig(disarm_delay=600.0))  # never disarms on its own

    def there_and_back() -> None:
        api.execute_behavior("TAKE_OFF", altitude=3)
        api.execute_behavior("LAND")

    engine = flown(drone, there_and_back)
    stop(engine)
    assert drone.telemetry().armed
    assert end_flight(engine) == []
    assert not drone.telemetry().armed and engine.log.events(kind="disarming")


def test_a_refused_disarm_leaves_the_drone_armed_and_says_so(stop):
    drone = Drone(default_world(), config=SimConfig(disarm_delay=600.0), refuse=("disarm",))

    def there_and_back() -> None:
        api.execute_behavior("TAKE_OFF", altitude=3)
        api.execute_behavior("LAND")

    engine = flown(drone, there_and_back)
    stop(engine)
    assert end_flight(engine, disarm_timeout=2.0) == ["the drone was left armed on the ground"]


def test_a_refused_landing_leaves_the_drone_in_the_air_and_says_why(stop):
    drone = Drone(default_world(), refuse=("land",))
    engine = flown(drone)
    stop(engine)
    height = f"{drone.telemetry().position[2]:.1f} m"
    faults = end_flight(engine, landing_timeout=10.0)
    assert len(faults) == 1 and faults[0].startswith(f"the drone was left in the air at {height} (landing failed:")
    assert "the pad is blocked" in faults[0]


def test_a_link_that_stays_down_is_waited_for_then_reported(stop):
    drone = Drone(default_world())
    engine = flown(drone)
    stop(engine)
    height = f"{drone.telemetry().position[2]:.1f} m"
    drone.drop_link(float("inf"))
    start = engine.now()
    faults = end_flight(engine, link_grace=5.0)
    assert engine.now() - start == pytest.approx(5.0, abs=0.2)  # tried for the grace time, on engine time
    assert faults[0].startswith(f"link lost at t={start:.1f} s with the drone in the air at {height}")
    assert "back at" not in faults[0]
    assert faults[1] == "the drone did not answer again: its state is unknown"
    assert engine.log.events(kind="link_not_back")


def test_a_link_back_within_the_grace_time_lets_the_drone_land(stop):
    drone = Drone(default_world())
    engine = flown(drone)
    stop(engine)
    height = f"{drone.telemetry().position[2]:.1f} m"
    drone.drop_link(3.0)
    faults = end_flight(engine, link_grace=10.0)
    t = drone.telemetry()
    assert t.landed_state == LandedState.ON_GROUND and not t.armed
    assert engine.log.events(kind="link_back") and engine.log.events(kind="landing")
    assert len(faults) == 1 and f"with the drone in the air at {height} (back at t=" in faults[0]
