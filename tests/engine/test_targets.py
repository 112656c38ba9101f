"""Motion with targets on the simulated drone in the default world (the rover drives a 12 x 4 m loop south of
home at 1 m/s, deck marker 42): landing on it and riding it, taking off from it, aligning over, tracking,
following and touching things the cameras see, and losing sight of them."""

import math

from aeroexec.drones import LandedState
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.behaviors.flight_control import heading_to, yaw_error
from aeroexec.engine.engine import Engine
from aeroexec.engine.execution.process import EngineSettings

ENDINGS = {"GOAL_ACHIEVED", "WRONG_PROGRESS", "TIME_OUT", "INTERRUPTED", "failed_preconditions"}


def make_engine(**extra):
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, settings=EngineSettings(extra=extra))
    engine.step(0.1)
    return engine


def execute(engine, name, arguments=None, seconds=120.0):
    """Activate ``name`` and tick until it ends; the event that ended it."""
    result = engine.coordinator.activate(name, arguments or {})
    assert result.accepted, result.message
    assert engine.run_until(lambda: not engine.coordinator.is_active(name), seconds), f"{name} still active"
    return [e for e in engine.log.events(behavior=name) if e.kind in ENDINGS][-1]


def hovering_at(point, yaw=None, **extra):
    engine = make_engine(**extra)
    assert execute(engine, "TAKE_OFF", {"ALTITUDE": point[2]}).kind == "GOAL_ACHIEVED"
    arguments = {"COORDINATES": list(point)}
    if yaw is not None:
        arguments["YAW_ANGLE_AT_THE_END"] = yaw
    assert execute(engine, "GO_TO_POINT", arguments).kind == "GOAL_ACHIEVED"
    return engine


def rover(engine):
    return engine.drone.world.platform_position(engine.now())


def tel(engine):
    return engine.drone.telemetry()


def flat(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])


def landed_on_the_rover():
    engine = hovering_at((0.0, -6.0, 3.0))
    event = execute(engine, "LAND_ON_MOVING_PLATFORM")
    assert event.kind == "GOAL_ACHIEVED", event
    return engine


def test_land_on_the_moving_rover_and_ride_it():
    engine = landed_on_the_rover()
    landed = engine.log.events(kind="drone_landed")
    assert landed and landed[-1].data.get("platform") == "rover"
    assert not engine.log.events(kind="drone_collision")
    t = tel(engine)
    assert t.landed_state is LandedState.ON_GROUND and abs(t.altitude - 0.5) < 0.01  # on the deck
    assert engine.memory.holds("flight_state(self, landed)")
    offset = flat(t.position, rover(engine))
    assert offset < 0.5
    start = t.position
    engine.step(6.0)  # the rover drives on and carries the (disarmed) drone
    t = tel(engine)
    assert flat(t.position, start) > 3.0
    assert abs(flat(t.position, rover(engine)) - offset) < 0.05 and abs(t.altitude - 0.5) < 0.01


def test_take_off_from_the_moving_rover():
    engine = landed_on_the_rover()
    engine.step(3.0)
    event = execute(engine, "TAKE_OFF_FROM_MOVING_PLATFORM", seconds=30.0)
    assert event.kind == "GOAL_ACHIEVED", event
    engine.step(2.0)
    t = tel(engine)
    assert t.landed_state is LandedState.IN_AIR and abs(t.altitude - 2.5) < 0.3  # 2 m above the deck
    assert engine.memory.holds("flight_state(self, hovering)")
    here = t.position
    engine.step(4.0)  # off the deck: no longer carried by the rover
    assert math.dist(tel(engine).position, here) < 0.2
    assert flat(tel(engine).position, rover(engine)) > 2.0


def test_align_over_the_red_box():
    engine = hovering_at((0.0, -1.0, 3.0))
    event = execute(engine, "ALIGN_OVER_IMAGE", {"IMAGE": "red_box"})
    assert event.kind == "GOAL_ACHIEVED", event
    engine.step(3.0)
    t = tel(engine)
    assert flat(t.position, (4.0, 2.0)) <= 0.35 and abs(t.altitude - 3.0) < 0.25
    assert "red_box" in [o.name for o in engine.drone.observations()]  # the bottom camera sees it below


def test_track_the_rover_turning_to_keep_it_in_view():
    engine = hovering_at((0.0, -5.0, 3.0))
    place = tel(engine).position
    assert engine.coordinator.activate("TRACK_OBJECT_IMAGE", {"IMAGE": "rover"}).accepted
    engine.step(3.0)
    yaws = []
    for _ in range(24):
        engine.step(1.0)
        t = tel(engine)
        yaws.append(t.yaw)
        assert yaw_error(t.yaw, heading_to(t.position, rover(engine))) < 15.0  # the rover stays centered
        assert math.dist(t.position, place) < 0.3  # it keeps its position
    assert max(yaws) - min(yaws) > 60.0  # it turned to follow the rover round its loop
    assert engine.coordinator.is_active("TRACK_OBJECT_IMAGE")
    assert engine.memory.holds("visible(rover)") and engine.memory.holds("position(rover, ?p)")
    assert engine.coordinator.inhibit("TRACK_OBJECT_IMAGE")
    engine.step(3.0)
    assert tel(engine).speed < 0.1  # it holds once stopped


def test_follow_the_rover_at_the_set_distance():
    engine = hovering_at((0.0, -6.0, 3.0), follow_distance=4.0)
    assert engine.coordinator.activate("FOLLOW_OBJECT_IMAGE", {"IMAGE": "rover"}).accepted
    engine.step(10.0)
    distances, flown, last = [], 0.0, tel(engine).position
    for _ in range(30):  # about one lap of the rover
        engine.step(1.0)
        t = tel(engine)
        distances.append(flat(t.position, rover(engine)))
        flown, last = flown + flat(t.position, last), t.position
        assert abs(t.altitude - 3.0) < 0.2
    assert all(3.3 < d < 4.7 for d in distances), distances
    assert abs(sum(distances) / len(distances) - 4.0) < 0.2
    assert flown > 20.0 and engine.coordinator.is_active("FOLLOW_OBJECT_IMAGE")


def test_follow_a_still_object_ends_at_the_distance():
    engine = hovering_at((0.0, -1.0, 3.0))
    event = execute(engine, "FOLLOW_OBJECT_IMAGE", {"IMAGE": "red_box"})
    assert event.kind == "GOAL_ACHIEVED", event
    assert abs(flat(tel(engine).position, (4.0, 2.0)) - 3.0) <= 0.35


def test_touch_the_blue_ball_and_climb_back():
    engine = hovering_at((0.0, -1.0, 3.0))
    event = execute(engine, "TOUCH_MOVING_OBJECT", {"IMAGE": "blue_ball"}, seconds=60.0)
    assert event.kind == "GOAL_ACHIEVED", event
    touched = engine.log.events(kind="drone_touched")
    assert [e.data["object"] for e in touched] == ["blue_ball"]
    assert not engine.log.events(kind="drone_collision") and not engine.log.events(kind="drone_landed")
    t = tel(engine)
    assert abs(t.altitude - 3.0) < 0.3 and flat(t.position, (-4.0, -3.0)) < 0.5


def test_losing_sight_of_the_rover_is_wrong_progress():
    engine = hovering_at((-14.0, -14.0, 3.0), yaw=0.0)  # the rover drives out of the camera's 12 m range going east
    in_view = lambda: "rover" in [o.name for o in engine.drone.observations()]  # noqa: E731
    assert engine.run_until(lambda: in_view() and rover(engine)[0] < -5.9, 40.0)  # at the loop's west end
    event = execute(engine, "TRACK_OBJECT_IMAGE", {"IMAGE": "rover"}, seconds=30.0)
    assert event.kind == "WRONG_PROGRESS" and "lost sight of rover" in event.detail, event
    assert flat(tel(engine).position, rover(engine)) > 10.0
    engine.step(3.0)
    assert tel(engine).landed_state is LandedState.IN_AIR and tel(engine).speed < 0.1


def test_a_target_never_seen_is_searched_for_one_turn():
    engine = hovering_at((0.0, -1.0, 3.0))
    event = execute(engine, "ALIGN_OVER_IMAGE", {"IMAGE": "purple_unicorn"}, seconds=30.0)
    assert event.kind == "WRONG_PROGRESS" and "purple_unicorn is not in sight" in event.detail, event
