"""Path and exploration planning: the A* planner on random worlds (never through an obstacle), enclosed and
blocked goals, the default world's tower, lawnmower coverage with memory, and both deliberative behaviors
run through an engine on the simulated drone."""

import dataclasses
import math

import pytest
from aeroexec.beliefs import ListTerm
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.drones.sim.shapes import Box, Cylinder
from aeroexec.drones.sim.world import Bounds
from aeroexec.engine.behaviors.planning import PLANNING_BEHAVIORS, PLANNING_PROCESSES, exploration_store
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.library import default_library, default_processes
from aeroexec.engine.planning.exploration import ExplorationPlanner, ExplorationSettings, lawnmower
from aeroexec.engine.planning.path_planner import PathPlanner, PlannerSettings, plan_path
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

MARGIN = 1.0
LOWER, UPPER = (-10.0, -10.0, 0.0), (10.0, 10.0, 8.0)


def world_with(obstacles, lower=LOWER, upper=UPPER):
    return dataclasses.replace(default_world(), bounds=Bounds(lower, upper), obstacles=tuple(obstacles),
                               markers=(), objects=(), platform=None)


def assert_safe(world, start, path, goal, margin=MARGIN):
    """Every segment keeps ``margin`` (sampled every 2 cm on the distance function), stays in bounds, ends at goal."""
    assert path, "expected a path"
    assert math.dist(path[-1], goal) < 1e-9
    points = [tuple(start), *path]
    for a, b in zip(points, points[1:], strict=False):
        assert world.bounds.contains(b), f"{b} leaves the bounds"
        assert world.segment_clear(a, b), f"{a} -> {b} crosses an obstacle"
        steps = max(1, math.ceil(math.dist(a, b) / 0.02))
        for n in range(steps + 1):
            p = tuple(a[i] + (b[i] - a[i]) * n / steps for i in range(3))
            assert world.distance_to_obstacle(p) >= margin - 1e-6, f"{p} on {a} -> {b} is too near an obstacle"


# Obstacles in the middle band, start on the west side and goal on the east one: most straight lines are blocked.
middle = st.floats(-6, 6, allow_nan=False)
coordinate = st.floats(-9.5, 9.5, allow_nan=False)
height = st.floats(0.5, 7.5, allow_nan=False)
boxes = st.builds(lambda x, y, z, sx, sy, sz, n: Box(f"box{n}", (x, y, z), (sx, sy, sz)),
                  middle, coordinate, height, st.floats(0.3, 8), st.floats(0.3, 8), st.floats(0.5, 8),
                  st.integers(0, 99))
cylinders = st.builds(lambda x, y, r, h, n: Cylinder(f"cyl{n}", (x, y), r, h),
                      middle, coordinate, st.floats(0.2, 2.5), st.floats(1, 8), st.integers(0, 99))
west = st.tuples(st.floats(-9.5, -4, allow_nan=False), coordinate, height)
east = st.tuples(st.floats(4, 9.5, allow_nan=False), coordinate, height)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(st.lists(st.one_of(boxes, cylinders), min_size=1, max_size=6), west, east)
def test_paths_in_random_worlds_keep_the_margin(obstacles, start, goal):
    world = world_with(obstacles)
    assume(world.distance_to_obstacle(start) >= MARGIN and world.distance_to_obstacle(goal) >= MARGIN)
    planner = PathPlanner(world, PlannerSettings(resolution=0.5, margin=MARGIN))
    path = planner.plan(start, goal)
    if path:
        assert_safe(world, start, path, goal)
    else:  # no path is only acceptable when the straight line is not clear either
        assert planner.reason
        steps = max(1, math.ceil(math.dist(start, goal) / 0.02))
        assert min(world.distance_to_obstacle(tuple(start[i] + (goal[i] - start[i]) * n / steps for i in range(3)))
                   for n in range(steps + 1)) < MARGIN + 1e-3


def shell(center, inner, thickness=0.5):
    """Six boxes enclosing a cube of half-size ``inner`` around ``center``."""
    cx, cy, cz = center
    outer = 2 * (inner + thickness)
    walls = []
    for axis in range(3):
        for sign in (-1, 1):
            c = [cx, cy, cz]
            c[axis] += sign * (inner + thickness / 2)
            size = [outer, outer, outer]
            size[axis] = thickness
            walls.append(Box(f"wall{axis}{sign}", tuple(c), tuple(size)))
    return walls


def test_an_enclosed_goal_has_no_path():
    world = world_with(shell((3.0, 3.0, 4.0), inner=2.5))
    planner = PathPlanner(world)
    assert planner.plan((-6, -6, 2), (3, 3, 4)) == []
    assert "enclosed" in planner.reason
    assert planner.plan((3, 3, 4), (3.5, 3.5, 4)) == [(3.5, 3.5, 4)]  # inside, the goal is in reach


def test_goals_inside_obstacles_or_out_of_bounds_have_no_path():
    world = default_world()
    planner = PathPlanner(world)
    assert planner.plan((0, 0, 2), (8, 8, 5)) == []  # inside the tower
    assert "obstacle" in planner.reason
    assert planner.plan((0, 0, 2), (8, 6.2, 5)) == []  # within the margin of its face
    assert planner.plan((0, 0, 2), (30, 0, 2)) == []
    assert "outside the bounds" in planner.reason


def test_a_path_behind_the_tower_goes_around_it():
    world = default_world()
    start, goal = (0.0, 0.0, 2.0), (11.0, 11.0, 2.0)
    assert not world.segment_clear(start, goal)
    path = plan_path(world, start, goal)
    assert 2 <= len(path) <= 5
    assert_safe(world, start, path, goal)
    from_ground = plan_path(world, (0.0, 0.0, 0.0), (12.0, 12.0, 3.0))
    assert_safe(world, (0.0, 0.0, 0.0), from_ground, (12.0, 12.0, 3.0))


def test_an_open_line_is_one_waypoint_and_no_map_is_a_straight_line():
    assert plan_path(default_world(), (0, 0, 2), (-3, -12, 4)) == [(-3, -12, 4)]
    assert plan_path(None, (0, 0, 2), (8, 8, 5)) == [(8, 8, 5)]


def test_lawnmower_covers_a_rectangle_and_a_triangle():
    square = lawnmower([(0, 0, 3), (10, 0, 3), (10, 10, 3), (0, 10, 3)], spacing=4.0)
    assert len(square) == len(set(square)) == 9
    assert {p[2] for p in square} == {3.0}
    assert square[:3] == [(2.0, 1.667, 3.0), (5.0, 1.667, 3.0), (8.0, 1.667, 3.0)]
    assert square[3][0] == 8.0  # the second line runs back
    for x in (0.5, 5, 9.5):  # every point of the region is within a spacing of a sweep point
        for y in (0.5, 5, 9.5):
            assert min(math.dist((x, y), p[:2]) for p in square) <= 4.0
    assert lawnmower([(0, 0, 1), (10, 10, 3)], spacing=4.0) == lawnmower(
        [(0, 0, 2), (10, 0, 2), (10, 10, 2), (0, 10, 2)], spacing=4.0)
    triangle = lawnmower([(0, 0, 2), (12, 0, 2), (0, 12, 2)], spacing=3.0)
    assert all(x + y <= 12 for x, y, _ in triangle)
    with pytest.raises(ValueError):
        lawnmower([(0, 0, 2)], 3.0)


def test_exploration_returns_each_point_once_then_nothing():
    region = [(-10, -10, 3), (10, -10, 3), (10, 10, 3), (-10, 10, 3)]
    planner = ExplorationPlanner(region, ExplorationSettings(footprint=5.0, overlap=0.0))
    seen, position = [], (-12.0, -12.0, 3.0)
    while (point := planner.next_point(position)) is not None:
        seen.append(point)
        position = point  # the drone flies there
    assert sorted(seen) == sorted(planner.points) and len(seen) == len(set(seen)) == 16
    assert planner.next_point(position) is None and planner.done


def test_exploration_starts_at_the_nearest_corner_and_gives_up_unreachable_points():
    region = [(0, 0, 3), (10, 10, 3)]
    planner = ExplorationPlanner(region, ExplorationSettings(footprint=5.0, overlap=0.0, max_attempts=2))
    first = planner.next_point((11.0, 11.0, 3.0))
    assert first == planner.points[0] == (7.5, 7.5, 3.0)  # starts at the corner nearest the drone
    assert planner.next_point(first) != first
    stuck = planner.next_point((50, 50, 3))
    assert planner.next_point((50, 50, 3)) != stuck and stuck in planner.skipped  # handed out twice: given up
    obstacle_world = world_with([Box("block", (2.5, 2.5, 3), (2, 2, 6))])
    assert (2.5, 2.5, 3.0) not in ExplorationPlanner(region, ExplorationSettings(footprint=5.0, overlap=0.0),
                                                     obstacle_world).points


def planning_engine(world):
    library = default_library()
    for cls in PLANNING_BEHAVIORS:
        library.register(cls)
    processes = default_processes()
    for name, factory in PLANNING_PROCESSES.items():
        processes.register(name, factory)
    return Engine(SimulatedDrone(world), obstacles=world, library=library, processes=processes)


def run_deliberative(engine, name, arguments):
    ended = []
    accepted = engine.coordinator.activate(name, arguments, on_end=lambda *end: ended.append(end))
    assert accepted.accepted, accepted
    assert engine.run_until(lambda: bool(ended), timeout=5.0)
    outcome, _, result = ended[0]
    assert outcome is Outcome.GOAL_ACHIEVED
    return result


def test_the_path_behavior_plans_around_the_tower_and_believes_the_path():
    world = default_world()
    engine = planning_engine(world)
    engine.step(0.2)
    result = run_deliberative(engine, "GENERATE_PATH_FREE_OF_OBSTACLES", {"DESTINATION": [12, 12, 3]})
    assert result[-1] == [12, 12, 3] and len(result) >= 2
    assert_safe(world, engine.drone.telemetry().position, [tuple(p) for p in result], (12, 12, 3))
    belief = engine.memory.matching("path(?D, ?P)")[0]
    assert belief.args[0] == (12.0, 12.0, 3.0) and list(belief.args[1]) == [tuple(p) for p in result]
    assert run_deliberative(engine, "GENERATE_PATH_FREE_OF_OBSTACLES", {"DESTINATION": [8, 8, 5]}) == []
    assert engine.memory.matching("path((8, 8, 5), ?P)")[0].args[1] == ListTerm()


def test_the_exploration_behavior_continues_the_coverage_between_calls():
    world = default_world()
    engine = planning_engine(world)
    engine.step(0.2)
    region = [[-4, -4, 3], [4, -4, 3], [4, 4, 3], [-4, 4, 3]]
    first = run_deliberative(engine, "GENERATE_NEXT_POINT_TO_EXPLORE", {"REGION": region})
    assert len(first) == 3
    assert engine.memory.holds("next_point_to_explore(?R, ?P)")
    store = exploration_store(engine.context)
    planner = store.planner(region)
    points = []
    for _ in range(len(planner.points) + 1):
        point = run_deliberative(engine, "GENERATE_NEXT_POINT_TO_EXPLORE", {"REGION": region})
        points.append(point)
        if point:
            store.mark(point)  # as if the drone had flown there
    assert points[0] == first and points[-1] == [] and len(points) == len(planner.points) + 1
    assert len({tuple(p) for p in points[:-1]}) == len(planner.points)
    assert engine.memory.matching("next_point_to_explore(?R, ?P)")[0].args[1] == ListTerm()


def test_without_an_obstacle_map_the_path_is_the_straight_line_and_the_log_says_so():
    library = default_library()
    for cls in PLANNING_BEHAVIORS:
        library.register(cls)
    engine = Engine(SimulatedDrone(default_world()), library=library)
    engine.step(0.2)
    assert run_deliberative(engine, "GENERATE_PATH_FREE_OF_OBSTACLES", {"DESTINATION": [12, 12, 3]}) == [[12, 12, 3]]
    assert any(e.kind == "path_planned" and "no obstacle map" in e.detail for e in engine.log.events())


def test_the_numpy_classification_frees_the_same_cells_as_the_distance_queries():
    from aeroexec.engine.planning.grid import OccupancyGrid, map_bounds

    world = default_world()

    class OneAtATime:  # the same map without distances_to_obstacle: classified block by block
        bounds = world.bounds

        def distance_to_obstacle(self, point):
            return world.distance_to_obstacle(point)

    lower, upper = map_bounds(world)
    for resolution in (0.5, 1.0):
        vectorized = OccupancyGrid(world, lower, upper, resolution, 1.0, 0.5)
        scalar = OccupancyGrid(OneAtATime(), lower, upper, resolution, 1.0, 0.5)
        assert vectorized.cells == scalar.cells
        assert 0 < vectorized.free_count < len(vectorized.cells)
