"""The simulated drone and the world's moving platform and objects: landing on the deck, riding it, taking off
from it, landing beside it, touching objects, the bottom camera. Driven by ``update(t)`` on a simulated clock."""

import math

import pytest
from aeroexec.drones import LandedState
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.world import Bounds, CameraSettings, Platform, World, WorldObject

HOME = (47.397742, 8.545594, 488.0)
DT = 0.05
SPEED = 0.1  # m/s: the platform creeps east along y = -3
PATH = ((0.0, -3.0, 0.5), (20.0, -3.0, 0.5))


def world(objects=()):
    return World(
        home=HOME,
        bounds=Bounds((-30.0, -30.0, 0.0), (30.0, 30.0, 20.0)),
        objects=tuple(objects),
        platform=Platform("cart", PATH, speed=SPEED, loop=False, marker_id=7),
        camera=CameraSettings(),
    )


class Clock:
    """Drives a drone tick by tick and collects its events."""

    def __init__(self, drone):
        self.drone, self.t, self.events = drone, 0.0, []

    def run(self, seconds, until=None):
        end = self.t + seconds
        while self.t < end - 1e-9:
            self.t = round(self.t + DT, 9)
            self.drone.update(self.t)
            self.events += self.drone.events()
            if until is not None and until(self.drone.telemetry()):
                return True
        return False

    def kinds(self):
        return [e.kind for e in self.events]


def hover_over(clock, point):
    drone = clock.drone
    assert drone.takeoff(3.0).ok
    clock.run(10.0, until=lambda t: abs(t.altitude - 3.0) < 0.1)
    assert drone.goto(point).ok
    clock.run(15.0, until=lambda t: math.dist(t.position, point) < 0.05 and t.speed < 0.05)


def land_on_the_deck():
    """Hover over the platform's path ahead of it and land as it comes under the drone."""
    clock = Clock(SimulatedDrone(world()))
    hover_over(clock, (1.5, -3.0, 3.0))
    clock.run(30.0, until=lambda t: clock.drone.world.platform_position(clock.t)[0] >= 1.05)
    assert clock.drone.land().ok
    assert clock.run(20.0, until=lambda t: t.landed_state is LandedState.ON_GROUND)
    return clock


def test_land_over_the_deck_touches_down_on_it_and_rides_along():
    clock = land_on_the_deck()
    drone = clock.drone
    landed = [e for e in clock.events if e.kind == "landed"]
    assert len(landed) == 1 and landed[0].data["platform"] == "cart" and "deck of 'cart'" in landed[0].detail
    assert "collision" not in clock.kinds() and drone.crashed is None
    t = drone.telemetry()
    assert t.altitude == pytest.approx(0.5, abs=0.01)  # on the deck, not the ground
    deck = drone.world.platform_position(clock.t)
    offset = (t.position[0] - deck[0], t.position[1] - deck[1])
    assert math.hypot(*offset) < 0.75
    clock.run(20.0)  # it auto-disarms on the deck and is still carried along
    t = drone.telemetry()
    assert not t.armed and t.landed_state is LandedState.ON_GROUND
    deck = drone.world.platform_position(clock.t)
    assert (t.position[0] - deck[0], t.position[1] - deck[1]) == pytest.approx(offset, abs=0.01)
    assert t.velocity[0] == pytest.approx(SPEED, abs=0.01)
    assert t.altitude == pytest.approx(0.5, abs=0.01)


def test_take_off_from_the_deck_climbs_from_it_and_leaves_it_behind():
    clock = land_on_the_deck()
    drone = clock.drone
    clock.run(5.0)
    assert drone.takeoff(2.5).ok
    assert clock.run(10.0, until=lambda t: t.landed_state is LandedState.IN_AIR and "takeoff_complete" in clock.kinds())
    clock.run(3.0)
    first = drone.telemetry()
    assert first.altitude == pytest.approx(2.5, abs=0.1)
    clock.run(10.0)  # the platform drives on 1 m; the drone hovers where it took off
    t = drone.telemetry()
    assert math.dist(t.position, first.position) < 0.05
    deck = drone.world.platform_position(clock.t)
    assert deck[0] - t.position[0] > 0.8
    assert drone.crashed is None and "collision" not in clock.kinds()


def test_landing_beside_the_deck_lands_on_the_ground():
    clock = Clock(SimulatedDrone(world()))
    hover_over(clock, (1.5, -1.5, 3.0))  # 1.5 m north of the platform's path: off the deck's edge
    assert clock.drone.land().ok
    assert clock.run(20.0, until=lambda t: t.landed_state is LandedState.ON_GROUND)
    landed = [e for e in clock.events if e.kind == "landed"]
    assert len(landed) == 1 and "platform" not in landed[0].data
    assert clock.drone.telemetry().altitude == 0.0
    before = clock.drone.telemetry().position
    clock.run(5.0)
    assert clock.drone.telemetry().position == before  # the ground does not move


def test_touching_an_object_is_reported_once_per_approach_and_is_no_collision():
    ball = WorldObject("ball", "blue", "sphere", (3.0, 0.0, 0.2))
    clock = Clock(SimulatedDrone(world([ball])))
    hover_over(clock, (3.0, 0.0, 3.0))
    assert "touched" not in clock.kinds()
    assert clock.drone.goto((3.0, 0.0, 0.6)).ok
    clock.run(10.0)
    touched = [e for e in clock.events if e.kind == "touched"]
    assert [e.data["object"] for e in touched] == ["ball"]
    assert clock.drone.crashed is None and clock.drone.telemetry().landed_state is LandedState.IN_AIR
    assert clock.drone.goto((3.0, 0.0, 3.0)).ok  # away and back: a second touch
    clock.run(8.0)
    assert clock.drone.goto((3.0, 0.0, 0.6)).ok
    clock.run(8.0)
    assert [e.data["object"] for e in clock.events if e.kind == "touched"] == ["ball", "ball"]


def test_the_bottom_camera_sees_what_is_right_below():
    ball = WorldObject("ball", "blue", "sphere", (3.0, 0.0, 0.2))
    drone = SimulatedDrone(world([ball]))
    clock = Clock(drone)
    hover_over(clock, (3.0, 0.0, 3.0))
    assert drone.camera.observe(drone.world, drone.telemetry().position, drone.telemetry().yaw, clock.t) == []
    assert [o.name for o in drone.observations()] == ["ball"]


def test_landing_on_the_deck_is_deterministic():
    def trajectory():
        clock = land_on_the_deck()
        clock.run(3.0)
        return clock.drone.telemetry().position, [(e.time, e.kind) for e in clock.events]

    assert trajectory() == trajectory()


def test_a_period_skips_riding_the_deck_only_when_riding_it_would_move_nothing():
    """The drone's period calls ``ride_deck`` only while the vehicle stands on the deck (``contacts.riding``): at
    every other period of a flight that lands on the deck, rides it and takes off again, riding would change
    nothing."""
    clock = land_on_the_deck()
    drone = clock.drone
    skipped = ridden = 0
    for period in range(300):
        if period == 60:
            assert drone.takeoff(2.5).ok
        clock.run(DT)
        v = drone._vehicle
        if v.contacts.riding is None:
            before = (v.position, v.velocity, v.airborne)
            v.ride_deck()
            assert (v.position, v.velocity, v.airborne) == before
            skipped += 1
        else:
            ridden += 1
    assert skipped > 10 and ridden > 10, "the flight neither rode the deck nor left it: the test tests nothing"
