"""The simulated drone on a simulated clock: take-off, go-to, landing, battery, failsafes, collisions,
geofence, camera, determinism. Every run is driven by ``update(t)`` calls, never by wall time."""

import math

import pytest
from aeroexec.drones import Drone, Failure, LandedState
from aeroexec.drones.sim import Camera, SimConfig, SimulatedDrone, default_world
from aeroexec.drones.sim.shapes import Box, Cylinder
from aeroexec.drones.sim.world import Bounds, CameraSettings, Marker, Platform, World, WorldObject

HOME = (47.397742, 8.545594, 488.0)
DT = 0.05  # the engine's tick in these tests


def field(*obstacles, markers=(), objects=(), platform=None, size=100.0, ceiling=40.0):
    """An open field ``2*size`` wide centred on home."""
    return World(
        home=HOME,
        bounds=Bounds((-size, -size, 0.0), (size, size, ceiling)),
        obstacles=tuple(obstacles),
        markers=tuple(markers),
        objects=tuple(objects),
        platform=platform,
        camera=CameraSettings(hfov=80.0, vfov=60.0, range=12.0, pitch=0.0),
    )


class Run:
    """A drone and a simulated clock advanced tick by tick, recording telemetry and events."""

    def __init__(self, drone: SimulatedDrone, t: float = 0.0):
        self.drone, self.t = drone, t
        self.log = []
        self.events = []

    def run(self, seconds: float, until=None):
        """Advance up to ``seconds``; stop early when ``until(telemetry)`` holds. Returns the time taken."""
        start = self.t
        end = self.t + seconds
        while self.t < end - 1e-9:
            self.t = round(self.t + DT, 6)
            self.drone.update(self.t)
            tel = self.drone.telemetry()
            self.log.append(tel)
            self.events.extend(self.drone.events())
            if until is not None and until(tel):
                break
        return self.t - start

    def kinds(self):
        return [e.kind for e in self.events]

    def event(self, kind):
        return next(e for e in self.events if e.kind == kind)


def airborne(altitude=10.0, world=None, config=None) -> Run:
    run = Run(SimulatedDrone(world or field(), config=config))
    assert run.drone.takeoff(altitude).ok
    run.run(30.0, until=lambda tel: tel.landed_state == LandedState.IN_AIR)
    assert run.drone.telemetry().landed_state == LandedState.IN_AIR
    run.log.clear()
    return run


def test_it_is_a_drone_that_starts_disarmed_on_the_ground_at_home():
    drone = SimulatedDrone()
    assert isinstance(drone, Drone)
    tel = drone.telemetry()
    assert tel.position == (0.0, 0.0, 0.0) and not tel.armed
    assert tel.landed_state == LandedState.ON_GROUND and tel.flight_mode == "MANUAL"
    assert tel.home == default_world().home and tel.battery_percent == 100.0
    assert tel.battery_voltage == pytest.approx(16.8)
    drone.update(3.5)
    assert drone.telemetry().time == 3.5
    drone.update(1.0)  # time never runs backwards
    assert drone.telemetry().time == 3.5


def test_takeoff_arms_and_climbs_vertically_at_the_climb_rate():
    config = SimConfig()
    run = Run(SimulatedDrone(field()))
    handle = run.drone.takeoff(10.0)
    assert handle.done and handle.ok
    assert run.drone.telemetry().armed and run.drone.telemetry().landed_state == LandedState.TAKING_OFF
    took = run.run(30.0, until=lambda tel: tel.landed_state == LandedState.IN_AIR)
    ideal = 10.0 / config.climb_rate
    assert ideal < took < ideal + 1.5  # accelerating and settling cost a little, not more
    tel = run.drone.telemetry()
    assert tel.altitude == pytest.approx(10.0, abs=0.15)
    assert math.hypot(tel.position[0], tel.position[1]) < 1e-6  # straight up
    climb = [t.velocity[2] for t in run.log]
    assert max(climb) == pytest.approx(config.climb_rate, abs=1e-6)  # never faster than the climb rate
    assert [t.landed_state for t in run.log[:3]] == [LandedState.TAKING_OFF] * 3
    assert run.kinds() == ["armed", "takeoff_complete"]
    assert tel.flight_mode == "HOLD"


def test_goto_flies_straight_at_cruise_speed_and_arrives():
    run = airborne()
    config = run.drone.config
    assert run.drone.goto((40.0, 30.0, 10.0)).ok  # 50 m away
    took = run.run(60.0, until=lambda tel: math.dist(tel.position, (40.0, 30.0, 10.0)) < 0.05)
    assert 50.0 / config.cruise_speed < took < 50.0 / config.cruise_speed + 4.0
    speeds = [math.hypot(t.velocity[0], t.velocity[1]) for t in run.log]
    assert max(speeds) == pytest.approx(config.cruise_speed, abs=1e-6)
    for tel in run.log:  # on the straight line from the start
        x, y, z = tel.position
        assert abs(3.0 * x - 4.0 * y) / 5.0 < 0.01 and z == pytest.approx(10.0, abs=0.1)
    assert "arrived" in run.kinds()
    assert run.drone.telemetry().yaw == pytest.approx(math.degrees(math.atan2(30.0, 40.0)), abs=0.5)


def test_goto_never_exceeds_the_maximum_speed_and_turns_at_the_yaw_rate_limit():
    run = airborne()
    config = run.drone.config
    assert run.drone.goto((-90.0, 0.0, 20.0), yaw=90.0, speed=50.0).ok  # asks for more than the drone can do
    run.run(60.0, until=lambda tel: math.dist(tel.position, (-90.0, 0.0, 20.0)) < 0.05)
    speeds = [math.hypot(t.velocity[0], t.velocity[1]) for t in run.log]
    assert max(speeds) == pytest.approx(config.max_speed, abs=1e-6)
    assert max(t.velocity[2] for t in run.log) <= config.max_climb_rate + 1e-9
    yaw_rates = [abs((b.yaw - a.yaw + 180.0) % 360.0 - 180.0) / DT for a, b in zip(run.log, run.log[1:], strict=False)]
    assert max(yaw_rates) <= config.yaw_rate + 1e-6
    assert run.drone.telemetry().yaw == pytest.approx(90.0)
    assert run.drone.telemetry().position == pytest.approx((-90.0, 0.0, 20.0), abs=0.05)


def test_landing_touches_down_gently_and_disarms_after_the_delay():
    run = airborne(8.0)
    assert run.drone.land().ok
    assert run.drone.telemetry().landed_state == LandedState.LANDING
    run.run(60.0, until=lambda tel: not tel.armed)
    landed, disarmed = run.event("landed"), run.event("disarmed")
    assert disarmed.time - landed.time == pytest.approx(run.drone.config.disarm_delay, abs=0.03)
    descent = [-t.velocity[2] for t in run.log]
    assert max(descent) <= run.drone.config.descent_rate + 1e-9
    last_meters = [-t.velocity[2] for t in run.log if 0.0 < t.altitude < 1.0]
    assert max(last_meters) <= run.drone.config.land_speed + 1e-9
    tel = run.drone.telemetry()
    assert tel.altitude == 0.0 and tel.landed_state == LandedState.ON_GROUND and tel.flight_mode == "MANUAL"
    refused = run.drone.land()
    assert refused.failure == Failure.DENIED and "already on the ground" in refused.reason


def test_return_to_launch_climbs_flies_home_and_lands():
    run = airborne(3.0)
    assert run.drone.goto((30.0, -20.0, 3.0)).ok
    run.run(30.0, until=lambda tel: math.dist(tel.position, (30.0, -20.0, 3.0)) < 0.1)
    assert run.drone.return_to_launch().ok
    assert run.drone.telemetry().flight_mode == "RETURN"
    run.run(120.0, until=lambda tel: not tel.armed)
    peak = max(t.altitude for t in run.log)
    assert peak == pytest.approx(run.drone.config.return_altitude, abs=0.2)
    tel = run.drone.telemetry()
    assert math.hypot(tel.position[0], tel.position[1]) < 0.3 and tel.altitude == 0.0
    assert run.kinds()[-2:] == ["landed", "disarmed"]


def test_the_battery_drains_with_time_and_more_when_moving():
    hover = airborne(world=field(size=200.0))
    moving = airborne(world=field(size=200.0))
    assert moving.drone.set_velocity((8.0, 6.0, 0.0)).ok  # 10 m/s
    start = hover.drone.telemetry().battery_percent
    hover.run(20.0)
    moving.run(20.0)
    hover_used = start - hover.drone.telemetry().battery_percent
    moving_used = start - moving.drone.telemetry().battery_percent
    per_second = 100.0 / (hover.drone.config.battery_hover_minutes * 60.0)
    assert hover_used == pytest.approx(20.0 * per_second, rel=0.01)
    assert moving_used > 1.25 * hover_used  # 10 m/s of 12 max: about 35 % more
    assert moving.drone.telemetry().battery_voltage < hover.drone.telemetry().battery_voltage
    idle = SimulatedDrone(field())
    idle.update(600.0)
    assert idle.telemetry().battery_percent == 100.0  # disarmed: nothing drains


def test_low_battery_triggers_the_failsafe_landing_and_blocks_flying():
    run = airborne(5.0, config=SimConfig(initial_battery_percent=8.0))
    run.run(120.0, until=lambda tel: tel.flight_mode == "LAND")
    failsafe = run.event("failsafe")
    assert "battery" in failsafe.detail and failsafe.data["battery_percent"] <= 7.0
    refused = run.drone.goto((5.0, 0.0, 5.0))
    assert refused.failure == Failure.DENIED and "failsafe" in refused.reason
    run.run(60.0, until=lambda tel: not tel.armed)
    assert run.drone.telemetry().altitude == 0.0
    assert run.kinds()[-2:] == ["landed", "disarmed"]
    refused = run.drone.arm()
    assert refused.failure == Failure.DENIED and "battery" in refused.reason
    assert not run.drone.takeoff(3.0).ok


def test_arming_rules_and_no_disarming_in_flight():
    run = airborne()
    assert run.drone.arm().failure == Failure.DENIED  # already flying
    refused = run.drone.disarm()
    assert refused.failure == Failure.DENIED and "flying" in refused.reason
    ground = SimulatedDrone(field())
    assert ground.arm().ok and ground.arm().ok  # arming twice on the ground is fine
    refused = ground.goto((1.0, 0.0, 2.0))
    assert refused.failure == Failure.DENIED and "take off first" in refused.reason
    ground.update(ground.config.preflight_disarm_delay + 0.1)
    assert not ground.telemetry().armed  # armed but never took off: auto-disarmed
    assert ground.disarm().ok


def test_flying_into_an_obstacle_is_a_collision_that_crashes_the_drone():
    world = field(Box("wall", center=(10.0, 0.0, 5.0), size=(1.0, 20.0, 10.0)))
    run = airborne(5.0, world=world)
    assert run.drone.goto((20.0, 0.0, 5.0)).ok  # straight through the wall
    run.run(30.0, until=lambda tel: tel.altitude == 0.0)
    collision = run.event("collision")
    assert collision.data["obstacle"] == "wall" and "wall" in collision.detail
    x_at_hit = collision.data["position"][0]
    assert 9.5 - 0.3 < x_at_hit < 9.5 - 0.3 + 0.2  # the drone's 0.3 m radius touched the face at x = 9.5
    tel = run.drone.telemetry()
    assert not tel.armed and tel.altitude == 0.0 and tel.landed_state == LandedState.ON_GROUND
    assert tel.position[0] < 9.5  # fell where it hit
    for handle in (run.drone.arm(), run.drone.takeoff(3.0), run.drone.goto((0.0, 0.0, 5.0))):
        assert handle.failure == Failure.DENIED and "crashed" in handle.reason
    assert run.drone.crashed and "wall" in run.drone.crashed


def test_flying_into_a_cylinder_also_collides():
    run = airborne(3.0, world=field(Cylinder("tree", center=(0.0, 8.0), radius=1.0, height=6.0)))
    assert run.drone.goto((0.0, 20.0, 3.0)).ok
    run.run(20.0)
    assert run.event("collision").data["obstacle"] == "tree"


def test_the_geofence_refuses_targets_outside_and_stops_a_drone_leaving_it():
    run = airborne(5.0, world=field(size=20.0))
    refused = run.drone.goto((30.0, 0.0, 5.0))
    assert refused.failure == Failure.DENIED and "outside the world's bounds" in refused.reason
    assert not run.drone.takeoff(50.0).ok  # above the ceiling
    assert run.drone.set_velocity((5.0, 0.0, 0.0)).ok  # east until the fence
    run.run(20.0)
    event = run.event("out_of_bounds")
    assert event.data["position"][0] > 20.0
    tel = run.drone.telemetry()
    assert tel.flight_mode == "HOLD" and tel.speed < 0.01
    assert 19.0 < tel.position[0] <= 20.0  # back inside, next to the fence
    assert run.kinds().count("out_of_bounds") == 1


def test_set_velocity_flies_at_the_commanded_velocity_within_limits():
    run = airborne(5.0)
    assert run.drone.set_velocity((3.0, -4.0, 1.0), yaw_rate=20.0).ok
    assert run.drone.telemetry().flight_mode == "OFFBOARD"
    run.run(4.0)
    tel = run.drone.telemetry()
    assert tel.velocity == pytest.approx((3.0, -4.0, 1.0))
    assert run.drone.set_velocity((100.0, 0.0, 0.0)).ok
    run.run(6.0)
    assert run.drone.telemetry().velocity[0] == pytest.approx(run.drone.config.max_speed)
    assert run.drone.hold().ok
    run.run(8.0)
    assert run.drone.telemetry().speed < 0.01 and run.drone.telemetry().flight_mode == "HOLD"


def test_set_mode_and_offboard_position_serve_the_mavlink_vehicle():
    drone = SimulatedDrone(field())
    run = Run(drone)
    assert drone.set_mode("TAKEOFF").ok
    run.run(20.0, until=lambda tel: tel.landed_state == LandedState.IN_AIR)
    assert drone.telemetry().altitude == pytest.approx(drone.config.default_takeoff_altitude, abs=0.15)
    assert drone.set_mode("OFFBOARD").ok and drone.telemetry().flight_mode == "OFFBOARD"
    assert drone.offboard_position((5.0, 5.0, 4.0), yaw=45.0).ok
    run.run(20.0)
    assert drone.telemetry().position == pytest.approx((5.0, 5.0, 4.0), abs=0.02)
    assert drone.telemetry().yaw == pytest.approx(45.0)
    assert drone.set_mode("ACRO").failure == Failure.UNSUPPORTED
    assert drone.set_mode("LAND").ok and drone.telemetry().flight_mode == "LAND"


def test_the_camera_sees_a_marker_in_front_within_range_and_in_sight():
    marker = Marker(id=5, position=(8.0, 0.0, 3.0), yaw=180.0, name="marker_5")  # faces west, toward home
    world = field(markers=[marker])
    camera = Camera.from_settings(world.camera)
    seen = camera.observe(world, (0.0, 0.0, 3.0), 0.0, 0.0)
    assert [(o.kind, o.marker_id) for o in seen] == [("marker", 5)]
    assert seen[0].distance == pytest.approx(8.0)
    assert camera.observe(world, (0.0, 0.0, 3.0), 180.0, 0.0) == []  # looking away
    assert camera.observe(world, (0.0, 0.0, 3.0), 60.0, 0.0) == []  # outside the 80 degree field of view
    assert camera.observe(world, (-5.0, 0.0, 3.0), 0.0, 0.0) == []  # 13 m: beyond the 12 m range
    assert camera.observe(world, (16.0, 0.0, 3.0), 180.0, 0.0) == []  # behind the marker: its back side
    assert camera.observe(world, (0.0, 0.0, 12.0), 0.0, 0.0) == []  # far above: outside the vertical view
    blocked = field(Box("crate", (4.0, 0.0, 3.0), (1.0, 1.0, 1.0)), markers=[marker])
    assert camera.observe(blocked, (0.0, 0.0, 3.0), 0.0, 0.0) == []  # hidden behind an obstacle
    assert [o.marker_id for o in camera.observe(blocked, (0.0, 0.0, 5.0), 0.0, 0.0)] == [5]  # seen over it


def test_the_drone_reports_objects_and_the_moving_platform_its_camera_sees():
    platform = Platform("rover", ((6.0, -20.0, 0.5), (6.0, 20.0, 0.5)), speed=2.0, loop=False, marker_id=42)
    world = World(
        home=HOME,
        bounds=Bounds((-50, -50, 0), (50, 50, 30)),
        platform=platform,
        objects=(WorldObject("red_ball", "red", "sphere", (5.0, 1.0, 0.2)),),
        camera=CameraSettings(hfov=80.0, vfov=60.0, range=12.0, pitch=-30.0),
    )
    drone = SimulatedDrone(world)
    assert drone.takeoff(3.0).ok
    rover_seen = []  # (time, observed position)
    deck_marker_seen = []
    for step in range(1, 501):
        t = step * DT
        drone.update(t)
        seen = {o.name: o for o in drone.observations()}
        if drone.telemetry().landed_state == LandedState.IN_AIR:
            assert seen["red_ball"].color == "red" and seen["red_ball"].shape == "sphere"
        if "rover" in seen:
            rover_seen.append((t, seen["rover"].position))
            assert seen["rover"].position == pytest.approx(world.platform_position(t))
        if "marker_42" in seen:
            deck_marker_seen.append(t)
    # The rover drives north along x = 6 and crosses the camera's view around t = 10 s.
    times = [t for t, _ in rover_seen]
    assert 6.5 < times[0] < 8.0 and 12.0 < times[-1] < 13.5
    assert rover_seen[0][1][1] < 0.0 < rover_seen[-1][1][1]
    assert deck_marker_seen and set(deck_marker_seen) <= set(times)


def test_same_world_seed_and_commands_give_the_same_trajectory():
    def mission(seed):
        config = SimConfig(position_noise_std=0.2)
        run = Run(SimulatedDrone(default_world(), config=config, seed=seed))
        run.drone.takeoff(5.0)
        run.run(6.0)
        run.drone.goto((10.0, -8.0, 6.0), yaw=30.0)
        run.run(7.3)
        run.drone.set_velocity((-1.0, 1.0, 0.0), yaw_rate=10.0)
        run.run(3.0)
        run.drone.return_to_launch()
        run.run(40.0)
        return [(t.time, t.position, t.velocity, t.yaw, t.battery_percent, t.flight_mode) for t in run.log], [
            (e.time, e.kind) for e in run.events
        ]

    first, second = mission(7), mission(7)
    assert first == second
    assert first[1][-1][1] == "disarmed"  # the mission ran to its end
    other = mission(8)
    assert other[0] != first[0]  # the seed drives the position noise
    assert [k for _, k in other[1]] == [k for _, k in first[1]]  # but not the flight itself


def test_telemetry_asked_again_is_the_same_answer_until_an_update_or_a_command_changes_the_state():
    run = airborne(5.0)
    first = run.drone.telemetry()
    assert run.drone.telemetry() is first  # nothing moved
    run.drone.update(run.t)  # not later: nothing moved either
    assert run.drone.telemetry() is first
    assert run.drone.land().ok  # a command answers at once in the telemetry, before the next update
    assert run.drone.telemetry().flight_mode == "LAND" and first.flight_mode == "HOLD"
    assert run.drone.set_mode("HOLD").ok
    assert run.drone.telemetry().flight_mode == "HOLD"
    run.run(DT)
    assert run.drone.telemetry().time == run.t > first.time


def test_telemetry_made_by_filling_its_slots_is_the_dataclass_of_the_same_fields():
    from dataclasses import FrozenInstanceError, fields

    from aeroexec.drones import Telemetry
    from aeroexec.drones.interface import telemetry_snapshot

    values = {f.name: (i + 0.5 if f.name != "landed_state" else LandedState.IN_AIR)
              for i, f in enumerate(fields(Telemetry))}
    made = telemetry_snapshot(*values.values())
    assert made == Telemetry(**values) and repr(made) == repr(Telemetry(**values))
    with pytest.raises(FrozenInstanceError):
        made.yaw = 1.0
    drone = SimulatedDrone(field(), config=SimConfig(wind=(1.0, 0.0), link_loss=(1.0, 2.0)))
    drone.arm()
    drone.takeoff(3.0)
    drone.update(1.5)
    t = drone.telemetry()
    assert (t.wind, t.ground_link, t.link_ok, t.home, t.position_accuracy) == ((1.0, 0.0), False, True, HOME, None)
