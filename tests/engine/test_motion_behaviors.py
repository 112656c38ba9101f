"""The motion behaviors flying the simulated drone on the simulated clock, through the coordinator: what an
operator would notice (where the drone ends, which way it faces, which events the log shows)."""

import dataclasses
import math

import pytest
from aeroexec.drones import CommandHandle, LandedState
from aeroexec.drones.sim import SimulatedDrone, default_world, load_world
from aeroexec.engine.behaviors.flight_control import wrap180
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome

TOL = 0.3  # m, EngineSettings.position_tolerance
YAW_TOL = 5.0  # degrees, EngineSettings.yaw_tolerance
ENDINGS = {o.value for o in Outcome}


def make_engine(drone=None):
    world = default_world()
    engine = Engine(drone or SimulatedDrone(world), obstacles=world)
    engine.step(0.1)
    return engine


def ending(engine, name):
    """The last event that ended (or refused) ``name``."""
    events = [e for e in engine.log.events(behavior=name) if e.kind in ENDINGS | {"failed_preconditions"}]
    return events[-1] if events else None


def execute(engine, name, arguments=None, seconds=60.0, watch=None, **options):
    """Activate ``name``, tick until it is no longer active (calling ``watch(telemetry)`` each tick), return
    the event that ended it."""
    result = engine.coordinator.activate(name, arguments or {}, **options)
    assert result.accepted, result.message

    def done():
        if watch is not None:
            watch(engine.drone.telemetry())
        return not engine.coordinator.is_active(name)

    assert engine.run_until(done, seconds), f"{name} still active after {seconds} s"
    return ending(engine, name)


def airborne(altitude=2.0, drone=None):
    engine = make_engine(drone)
    assert execute(engine, "TAKE_OFF", {"ALTITUDE": altitude}).kind == "GOAL_ACHIEVED"
    engine.step(1.0)
    return engine


def tel(engine):
    return engine.drone.telemetry()


def holding_still(engine, seconds=4.0):
    """Let the drone settle, then check that it stays put, armed and in the air."""
    engine.step(seconds)
    before = tel(engine).position
    engine.step(2.0)
    t = tel(engine)
    assert t.armed and t.landed_state is LandedState.IN_AIR
    assert t.speed < 0.05, t
    assert math.dist(before, t.position) < 0.05
    return t


# -- taking off, hovering, landing ---------------------------------------------------------------------------
def test_take_off_reaches_the_altitude_and_logs_goal_achieved():
    engine = make_engine()
    event = execute(engine, "TAKE_OFF", {"ALTITUDE": 3.0})
    assert event.kind == "GOAL_ACHIEVED"
    t = tel(engine)
    assert t.landed_state is LandedState.IN_AIR and abs(t.altitude - 3.0) <= 0.25


def test_take_off_without_altitude_uses_the_default_altitude():
    engine = make_engine()
    assert execute(engine, "TAKE_OFF").kind == "GOAL_ACHIEVED"
    engine.step(1.0)
    assert abs(tel(engine).altitude - engine.settings.default_altitude) <= 0.1


def test_keep_hovering_is_activated_by_reaction_when_take_off_ends():
    engine = make_engine()
    execute(engine, "TAKE_OFF")
    engine.step(0.5)
    assert engine.coordinator.is_active("KEEP_HOVERING")
    reactive = engine.log.events(kind="reactive", behavior="KEEP_HOVERING")
    goal = engine.log.events(kind="GOAL_ACHIEVED", behavior="TAKE_OFF")
    assert reactive and goal and reactive[0].time >= goal[0].time
    holding_still(engine)


def test_land_ends_on_the_ground():
    engine = airborne()
    assert execute(engine, "LAND").kind == "GOAL_ACHIEVED"
    assert tel(engine).landed_state is LandedState.ON_GROUND
    assert tel(engine).altitude < 0.05
    engine.step(3.0)
    assert not tel(engine).armed  # the drone disarms itself after landing
    assert not engine.coordinator.is_active("KEEP_HOVERING")


def test_keep_hovering_fails_when_the_drone_lands_on_its_own():
    engine = airborne()
    assert engine.coordinator.is_active("KEEP_HOVERING")
    engine.drone.land()  # e.g. the pilot's switch
    engine.step(0.5)
    event = ending(engine, "KEEP_HOVERING")
    assert event.kind == "WRONG_PROGRESS" and "landing on its own" in event.detail


# -- going to points ------------------------------------------------------------------------------------------
def test_go_to_point_arrives_with_the_yaw_asked():
    engine = airborne()
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [4, -3, 3], "YAW_ANGLE_AT_THE_END": 90})
    assert event.kind == "GOAL_ACHIEVED"
    t = tel(engine)
    assert math.dist(t.position, (4, -3, 3)) <= TOL
    assert abs(wrap180(t.yaw - 90)) <= YAW_TOL


def test_go_to_point_relative_looks_at_the_point_asked():
    engine = airborne()
    engine.step(1.0)
    x, y, z = tel(engine).position
    event = execute(engine, "GO_TO_POINT", {"RELATIVE_COORDINATES": [-3, 2, 1],
                                            "POINT_TO_LOOK_AT_THE_END": [x - 3, y - 5, z + 1]})
    assert event.kind == "GOAL_ACHIEVED"
    t = tel(engine)
    assert math.dist(t.position, (x - 3, y + 2, z + 1)) <= TOL
    assert abs(wrap180(t.yaw - (-90))) <= YAW_TOL  # the point is due south of the destination


@pytest.mark.parametrize("final_yaw", [180, -112])  # -112: close to the last heading toward the point
def test_go_to_point_looks_at_a_point_during_flight_and_turns_to_its_final_yaw(final_yaw):
    engine = airborne()
    look = (0.0, -15.0, 2.0)
    errors = []

    def watch(t):
        if 4.5 < t.position[0] < 6.5:  # on the way, once it has had time to turn (45 deg/s)
            errors.append(abs(wrap180(t.yaw - math.degrees(math.atan2(look[1] - t.position[1],
                                                                        look[0] - t.position[0])))))

    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [8, 0, 2], "POINT_TO_LOOK_DURING_FLIGHT": list(look),
                                            "YAW_ANGLE_AT_THE_END": final_yaw, "SPEED": 2.0}, watch=watch)
    assert event.kind == "GOAL_ACHIEVED"
    assert errors and max(errors) < 15.0
    assert abs(wrap180(tel(engine).yaw - final_yaw)) <= YAW_TOL


def test_go_to_point_time_sets_the_speed():
    engine = airborne()
    start = engine.now()
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [8, 0, 2], "TIME": round(start + 8.0)})
    assert event.kind == "GOAL_ACHIEVED"
    assert 7.0 <= event.time - start <= 11.0  # at cruise speed it would take about 3 s


def test_go_to_point_already_there_has_already_been_achieved():
    engine = airborne()
    here = tel(engine).position
    result = engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": list(here)})
    assert not result.accepted and result.outcome is Outcome.GOAL_ACHIEVED
    assert "The goal of behavior GO_TO_POINT has already been achieved" in result.message


def test_go_to_point_before_take_off_fails_its_preconditions():
    engine = make_engine()
    result = engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": [3, 0, 2]})
    assert not result.accepted and result.outcome is Outcome.FAILED_PRECONDITIONS
    assert "preconditions are not satisfied" in result.message and "flight_state" in result.message


def test_go_to_point_flies_around_an_obstacle_on_the_way():
    engine = airborne()
    world = engine.context.obstacles
    nearest = []
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [12, 12, 2]},  # the tower is on the straight line
                    watch=lambda t: nearest.append(world.distance_to_obstacle(t.position)))
    assert event.kind == "GOAL_ACHIEVED"
    assert math.dist(tel(engine).position, (12, 12, 2)) <= 0.3
    assert min(nearest) > 0.8  # kept (nearly) the planner's 1 m margin all the way


def test_go_to_point_without_an_obstacle_map_flies_straight_and_hits_what_is_there():
    engine = Engine(SimulatedDrone(default_world()))  # nothing known of the obstacles
    assert execute(engine, "TAKE_OFF", {"ALTITUDE": 2.0}).kind == "GOAL_ACHIEVED"
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [12, 12, 2]})
    assert event.kind == "WRONG_PROGRESS" and "tower" in event.detail


def test_go_to_point_outside_the_bounds_is_refused_before_flying():
    engine = airborne()
    result = engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": [30, 0, 2]})
    assert not result.accepted and result.outcome is Outcome.FAILED_PRECONDITIONS
    assert "The destination is too far for behavior GO_TO_POINT" in result.message


def test_go_to_point_outside_the_bounds_without_a_map_ends_with_the_drones_reason():
    engine = Engine(SimulatedDrone(default_world()))
    assert execute(engine, "TAKE_OFF", {"ALTITUDE": 2.0}).kind == "GOAL_ACHIEVED"
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [30, 0, 2]})
    assert event.kind == "WRONG_PROGRESS" and "geofence" in event.detail
    holding_still(engine)


def test_go_to_point_to_an_enclosed_point_meets_an_impassable_barrier(tmp_path):
    world_file = tmp_path / "pen.yaml"
    world_file.write_text(
        "home: {lat: 47.397742, lon: 8.545594, alt: 488.0}\n"
        "bounds: {min: [-20, -20, 0], max: [20, 20, 10]}\n"
        "obstacles:\n"
        "  - {name: north, type: box, center: [10, 15, 5], size: [12, 1, 10]}\n"
        "  - {name: south, type: box, center: [10, 5, 5], size: [12, 1, 10]}\n"
        "  - {name: east, type: box, center: [15.5, 10, 5], size: [1, 11, 10]}\n"
        "  - {name: west, type: box, center: [4.5, 10, 5], size: [1, 11, 10]}\n"
        "  - {name: roof, type: box, center: [10, 10, 9.5], size: [12, 11, 1]}\n")
    world = load_world(world_file)
    engine = Engine(SimulatedDrone(world), obstacles=world)
    assert execute(engine, "TAKE_OFF", {"ALTITUDE": 2.0}).kind == "GOAL_ACHIEVED"
    before = tel(engine).position
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [10, 10, 4]})  # the search runs on the planning worker
    assert event.kind == "FAILED_PRECONDITIONS"
    assert "There is an impassable barrier to complete behavior GO_TO_POINT" in event.detail
    assert "enclosed" in event.detail
    assert math.dist(before, tel(engine).position) < 0.3  # the drone held while the planner searched


def test_go_to_point_with_too_short_a_timeout_times_out_and_holds():
    engine = airborne()
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [10, 0, 2]}, timeout=0.5)
    assert event.kind == "TIME_OUT"
    t = holding_still(engine)
    assert t.position[0] < 8.0


def test_follow_path_passes_every_point():
    engine = airborne()
    path = [[3, 0, 2], [3, 3, 3], [0, 3, 2], [0, 0, 2]]
    nearest = [math.inf] * len(path)

    def watch(t):
        for i, p in enumerate(path):
            nearest[i] = min(nearest[i], math.dist(t.position, p))

    assert execute(engine, "FOLLOW_PATH", {"PATH": path}, watch=watch).kind == "GOAL_ACHIEVED"
    assert max(nearest) <= TOL
    assert math.dist(tel(engine).position, path[-1]) <= TOL


# -- turning --------------------------------------------------------------------------------------------------
def test_rotate_to_an_absolute_angle():
    engine = airborne()
    here = tel(engine).position
    assert execute(engine, "ROTATE", {"ANGLE": 120}).kind == "GOAL_ACHIEVED"
    t = tel(engine)
    assert abs(wrap180(t.yaw - 120)) <= YAW_TOL
    assert math.dist(t.position, here) < 0.1  # in place


def test_rotate_direction_forces_the_long_way_round():
    engine = airborne()
    yaws = []
    event = execute(engine, "ROTATE", {"ANGLE": 90, "DIRECTION": "CLOCKWISE"}, watch=lambda t: yaws.append(t.yaw))
    assert event.kind == "GOAL_ACHIEVED"
    assert abs(wrap180(tel(engine).yaw - 90)) <= YAW_TOL
    assert any(abs(wrap180(y + 90)) < 10 for y in yaws)  # it went through south


def test_rotate_a_full_relative_turn():
    engine = airborne()
    start = tel(engine).yaw
    yaws = []
    event = execute(engine, "ROTATE", {"RELATIVE_ANGLE": 360}, watch=lambda t: yaws.append(t.yaw))
    assert event.kind == "GOAL_ACHIEVED"
    assert abs(wrap180(tel(engine).yaw - start)) <= YAW_TOL
    assert any(abs(wrap180(y - start - 180)) < 10 for y in yaws)


def test_rotate_to_where_it_faces_has_already_been_achieved():
    engine = airborne()
    result = engine.coordinator.activate("ROTATE", {"ANGLE": round(tel(engine).yaw)})
    assert result.outcome is Outcome.GOAL_ACHIEVED and "already been achieved" in result.message


def test_look_at_a_point_faces_it():
    engine = airborne()
    x, y, _ = tel(engine).position
    assert execute(engine, "LOOK_AT_A_POINT", {"COORDINATES": [x - 5, y - 5, 0]}).kind == "GOAL_ACHIEVED"
    assert abs(wrap180(tel(engine).yaw - (-135))) <= YAW_TOL


# -- recurrent motions --------------------------------------------------------------------------------------
@pytest.mark.parametrize(("direction", "heading", "axis"), [
    ("FORWARD", 90.0, (0, 1, 0)), ("LEFT", 90.0, (-1, 0, 0)), ("RIGHT", 0.0, (0, -1, 0)),
    ("BACKWARD", 0.0, (-1, 0, 0)), ("UPWARD", 0.0, (0, 0, 1)), ("DOWNWARD", 0.0, (0, 0, -1)),
])
def test_keep_moving_goes_the_right_way_and_holds_when_inhibited(direction, heading, axis):
    engine = airborne(altitude=4.0)
    if heading:
        execute(engine, "ROTATE", {"ANGLE": heading})
    start = tel(engine).position
    assert engine.coordinator.activate("KEEP_MOVING", {"DIRECTION": direction, "SPEED": 1.0}).accepted
    engine.step(2.0)
    moved = [p - s for p, s in zip(tel(engine).position, start, strict=True)]
    along = sum(m * a for m, a in zip(moved, axis, strict=True))
    assert along > 1.0 and math.sqrt(sum(m * m for m in moved) - along * along) < 0.1
    assert engine.coordinator.inhibit("KEEP_MOVING")
    assert ending(engine, "KEEP_MOVING").kind == "INTERRUPTED"
    holding_still(engine)


def _angle(point, center):
    return math.degrees(math.atan2(point[1] - center[1], point[0] - center[0]))


def test_keep_loitering_stays_on_its_circle_clockwise():
    engine = airborne(altitude=3.0)
    center = tel(engine).position
    assert engine.coordinator.activate("KEEP_LOITERING", {"SHAPE": "CIRCLE", "RADIUS": 3.0, "CLOCKWISE": True}).accepted
    engine.step(10.0)
    samples = []
    for _ in range(100):
        engine.step(0.15)
        samples.append(tel(engine).position)
    radii = [math.dist(p[:2], center[:2]) for p in samples]
    assert max(abs(r - 3.0) for r in radii) < 0.3
    assert max(abs(p[2] - center[2]) for p in samples) < 0.2
    turned = sum(wrap180(_angle(b, center) - _angle(a, center)) for a, b in zip(samples, samples[1:], strict=False))
    assert turned < -180  # more than half a turn, clockwise
    assert engine.coordinator.is_active("KEEP_LOITERING")


def test_keep_loitering_square_after_its_delay():
    engine = airborne(altitude=3.0)
    center = tel(engine).position
    assert engine.coordinator.activate("KEEP_LOITERING", {"SHAPE": "SQUARE", "SIDE": 4.0, "DELAY": 3.0,
                                                          "CLOCKWISE": False}).accepted
    engine.step(2.5)
    assert math.dist(tel(engine).position, center) < 0.1  # still waiting
    engine.step(12.0)
    samples = []
    for _ in range(60):
        engine.step(0.25)
        samples.append(tel(engine).position)
    for x, y, _ in samples:  # on the square's outline: one coordinate at +-2 m, the other within it
        dx, dy = abs(x - center[0]), abs(y - center[1])
        assert max(dx, dy) == pytest.approx(2.0, abs=0.4) and min(dx, dy) <= 2.4
    turned = sum(wrap180(_angle(b, center) - _angle(a, center)) for a, b in zip(samples, samples[1:], strict=False))
    assert turned > 180  # counterclockwise


def test_flip_jogs_and_comes_back():
    engine = airborne(altitude=3.0)
    start = tel(engine).position
    farthest = [0.0]

    def watch(t):
        farthest[0] = max(farthest[0], math.dist(t.position, start))

    assert execute(engine, "FLIP", {"DIRECTION": "LEFT"}, watch=watch).kind == "GOAL_ACHIEVED"
    assert farthest[0] > 1.0
    assert math.dist(tel(engine).position, start) <= TOL


# -- stopping and failing ------------------------------------------------------------------------------------
STOPPABLE = [
    ("TAKE_OFF", {"ALTITUDE": 5.0}, False), ("LAND", {}, True), ("KEEP_HOVERING", {}, True),
    ("KEEP_MOVING", {"DIRECTION": "FORWARD", "SPEED": 3.0}, True), ("ROTATE", {"RELATIVE_ANGLE": 300}, True),
    ("GO_TO_POINT", {"COORDINATES": [-5, -10, 4]}, True), ("FOLLOW_PATH", {"PATH": [[5, 0, 2], [5, 5, 2]]}, True),
    ("LOOK_AT_A_POINT", {"COORDINATES": [-5, -5, 2]}, True), ("KEEP_LOITERING", {"RADIUS": 4.0}, True),
    ("FLIP", {"DIRECTION": "BACK"}, True),
]


@pytest.mark.parametrize(("name", "arguments", "flying"), STOPPABLE, ids=[s[0] for s in STOPPABLE])
@pytest.mark.parametrize("ticks", [1, 15])
def test_every_behavior_stopped_at_any_tick_leaves_the_drone_holding(name, arguments, flying, ticks):
    engine = airborne() if flying else make_engine()
    if flying:
        engine.coordinator.inhibit("KEEP_HOVERING")  # so that nothing else commands the drone after the stop
    assert engine.coordinator.activate(name, arguments).accepted
    engine.step(ticks * engine.period)
    assert engine.coordinator.inhibit(name)
    assert ending(engine, name).kind == "INTERRUPTED"
    engine.step(4.0)
    t = tel(engine)
    if t.landed_state is LandedState.ON_GROUND:  # TAKE_OFF stopped before it left the ground
        assert not flying and t.altitude == 0.0
        return
    holding_still(engine, 0.0)


class SlowLink(SimulatedDrone):
    """A drone whose go-to is never answered."""

    def goto(self, position, yaw=None, speed=None):
        return CommandHandle("goto")


class LosesLink(SimulatedDrone):
    """A drone whose link drops at a given time."""

    drop_at = 1e9

    def telemetry(self):
        t = super().telemetry()
        return t if t.time < self.drop_at else dataclasses.replace(t, link_ok=False)


class Frozen(SimulatedDrone):
    """A drone that accepts go-tos and ignores them."""

    def goto(self, position, yaw=None, speed=None):
        return CommandHandle.succeeded("goto")


@pytest.mark.parametrize(("drone_class", "reason", "after"), [
    (SlowLink, "the drone did not accept goto within 10 s", "command_timeout"),
    (LosesLink, "the link to the drone is lost", None),
    (Frozen, "no progress toward (5.0, 0.0, 2.0) (5.0 m away) for 8 s", "stall_time"),
], ids=["command-not-accepted", "link-lost", "no-progress"])
def test_a_drone_that_does_not_answer_or_move_gives_wrong_progress(drone_class, reason, after):
    drone = drone_class(default_world())
    engine = airborne(drone=drone)
    drone.drop_at = engine.now() + 1.0
    event = execute(engine, "GO_TO_POINT", {"COORDINATES": [5, 0, 2]})
    assert event.kind == "WRONG_PROGRESS" and f"({reason})" in event.detail
    started = engine.log.events(kind="activated", behavior="GO_TO_POINT")[-1].time
    if after is not None:  # the time the settings allow
        assert event.time - started == pytest.approx(getattr(engine.settings, after), abs=0.1)


# -- the common checks' fast path ------------------------------------------------------------------------------
def _checks_called_every_period(self):
    """``MotionBehavior.on_run`` as it was, calling both common checks every period: the slow path."""
    t = self.telemetry()
    if not t.link_ok:
        return self.fail("the link to the drone is lost")
    self._was_armed = self._was_armed or t.armed
    trouble = self._command_trouble() or self._flight_trouble(t)
    if trouble:
        return self.fail(trouble)
    return self.step(t)


def _flown_and_landed_by_the_drone() -> list[tuple]:
    """A take-off, a flight to a point, and a flight the drone ends by landing on its own (its land command sent
    behind the behavior's back): each common check finds nothing, then trouble."""
    engine = make_engine()
    execute(engine, "TAKE_OFF", {"ALTITUDE": 3})
    execute(engine, "GO_TO_POINT", {"COORDINATES": [2.0, 1.0, 3.0]})
    assert engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": [15.0, 0.0, 3.0], "SPEED": 0.5}).accepted
    engine.step(2.0)
    engine.drone.land()
    engine.step(10.0)
    return [(e.time, e.kind, e.behavior, e.detail) for e in engine.log.events()]


def test_the_common_checks_skipped_in_the_air_end_the_flight_as_calling_them_every_period(monkeypatch):
    from aeroexec.engine.behaviors.flight_control import MotionBehavior

    fast = _flown_and_landed_by_the_drone()
    assert any(kind == "WRONG_PROGRESS" and "landing on its own" in detail for _, kind, _, detail in fast), \
        "the drone's landing did not end the flight: the test tests nothing"
    monkeypatch.setattr(MotionBehavior, "on_run", _checks_called_every_period)
    assert _flown_and_landed_by_the_drone() == fast


def test_the_flight_check_skipped_for_a_drone_armed_in_the_air_finds_no_trouble():
    engine = airborne()
    assert engine.coordinator.activate("KEEP_HOVERING").accepted
    process = engine.coordinator.active()["KEEP_HOVERING"].process
    t = tel(engine)
    for was_armed in (True, False):
        for needs_flight in (True, False):
            process._was_armed, process.needs_flight = was_armed, needs_flight
            assert process._flight_trouble(dataclasses.replace(t, armed=True, landed_state=LandedState.IN_AIR)) is None
    engine.step(0.5)
    assert process._commands == [] and process._answered  # the command check's fast path: nothing waits
    since = process.progress.since
    assert process._command_trouble() is None and process.progress.since == since and process._commands == []
