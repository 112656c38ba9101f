"""The simulated world: the default world, geometry queries, the moving platform, world-file errors, geodesy."""

import math

import pytest
from aeroexec.drones.geodesy import enu_to_geodetic, geodetic_to_enu
from aeroexec.drones.sim import WorldError, default_world, load_world
from aeroexec.drones.sim.shapes import Box, Cylinder
from aeroexec.drones.sim.world import Bounds, Platform, World

HOME = (47.397742, 8.545594, 488.0)

GOOD = """\
name: test
home: {lat: 47.397742, lon: 8.545594, alt: 488.0}
bounds: {min: [-10, -10, 0], max: [10, 10, 10]}
obstacles:
  - {name: block, type: box, center: [5, 0, 2], size: [2, 2, 4]}
  - {name: post, type: cylinder, center: [-5, 0], radius: 1, height: 6}
markers:
  - {id: 7, position: [3.95, 0, 1], yaw: 180}
objects:
  - {name: red_ball, color: Red, shape: sphere, position: [0, 5, 0.2]}
platform: {name: cart, path: [[0, -5, 0.3], [4, -5, 0.3]], speed: 2, loop: false}
camera: {hfov: 90, range: 8}
"""


def write(tmp_path, text, name="world.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_default_world_is_a_40_m_field_with_obstacles_markers_objects_and_a_platform():
    world = default_world()
    lower, upper = world.bounds.lower, world.bounds.upper
    assert [hi - lo for lo, hi in zip(lower, upper, strict=True)] == [40.0, 40.0, 20.0]
    assert len(world.obstacles) >= 3 and len(world.markers) >= 6 and len(world.objects) >= 3
    assert {type(o) for o in world.obstacles} == {Box, Cylinder}
    assert world.platform is not None and world.platform.speed > 0
    assert world.distance_to_obstacle((0.0, 0.0, 0.0)) > 2.0  # room to take off at home
    for marker in world.markers:
        assert world.inside(marker.position), marker
        assert world.collides(marker.position) is None, marker  # in front of their walls, not inside


def test_a_world_file_loads_into_records(tmp_path):
    world = load_world(write(tmp_path, GOOD))
    assert world.name == "test" and world.home == HOME
    assert world.source.endswith("world.yaml")
    assert [o.name for o in world.obstacles] == ["block", "post"]
    assert world.marker(7).name == "marker_7" and world.marker(7).normal == pytest.approx((-1.0, 0.0, 0.0))
    assert world.objects[0].color == "red"  # normalized
    assert world.camera.hfov == 90.0 and world.camera.range == 8.0 and world.camera.vfov == 60.0  # default kept
    assert world.platform.loop is False


def test_distance_collision_and_line_of_sight_queries(tmp_path):
    world = load_world(write(tmp_path, GOOD))
    assert world.distance_to_obstacle((0.0, 0.0, 2.0)) == pytest.approx(4.0)  # block's west face at x=4
    assert world.distance_to_obstacle((5.0, 0.0, 7.0)) == pytest.approx(3.0)  # above the block's top at z=4
    assert world.distance_to_obstacle((-5.0, 3.0, 1.0)) == pytest.approx(2.0)  # post's side
    assert world.distance_to_obstacle((5.0, 0.0, 2.0)) == 0.0  # inside
    assert world.collides((3.8, 0.0, 2.0), radius=0.3).name == "block"
    assert world.collides((3.6, 0.0, 2.0), radius=0.3) is None
    assert world.collides((-5.0, 1.2, 5.0), radius=0.3).name == "post"
    assert not world.segment_clear((0.0, 0.0, 2.0), (8.0, 0.0, 2.0))  # through the block
    assert world.segment_clear((0.0, 0.0, 5.0), (8.0, 0.0, 5.0))  # over it
    assert not world.segment_clear((-8.0, 0.5, 3.0), (-2.0, 0.5, 3.0))  # through the post
    assert world.segment_clear((-8.0, 1.5, 3.0), (-2.0, 1.5, 3.0))  # beside it
    assert world.segment_clear((-5.0, -3.0, 7.0), (-5.0, 3.0, 7.0))  # above it
    assert world.inside((9.9, -9.9, 9.9)) and not world.inside((0.0, 0.0, 10.5))
    assert World(home=HOME, bounds=Bounds((-1, -1, 0), (1, 1, 1))).distance_to_obstacle((0, 0, 0)) == math.inf


def test_the_platform_moves_along_its_path_and_turns_back_or_loops(tmp_path):
    world = load_world(write(tmp_path, GOOD))
    assert world.platform_position(0.0) == pytest.approx((0.0, -5.0, 0.3))
    assert world.platform_position(1.0) == pytest.approx((2.0, -5.0, 0.3))  # 2 m/s
    assert world.platform_position(2.0) == pytest.approx((4.0, -5.0, 0.3))
    assert world.platform_position(3.0) == pytest.approx((2.0, -5.0, 0.3))  # back and forth
    loop = Platform("p", ((0, 0, 0), (3, 0, 0), (3, 4, 0)), speed=1.0, loop=True)
    assert loop.position(5.0) == pytest.approx((3.0, 2.0, 0.0))
    assert loop.position(9.5) == pytest.approx((1.5, 2.0, 0.0))  # closing leg back to the start
    assert loop.position(12.0 + 1.0) == pytest.approx((1.0, 0.0, 0.0))  # perimeter 12: round again
    assert World(home=HOME, bounds=Bounds((-1, -1, 0), (1, 1, 1))).platform_position(3.0) is None


BAD_WORLDS = [
    ("unknown key", GOOD.replace("camera: {hfov: 90", "camera: {zoom: 2, hfov: 90"), 12, "unknown key 'zoom'"),
    ("top-level typo", GOOD + "obstacle: []\n", 13, "unknown key 'obstacle'"),
    ("wrong type", GOOD.replace("speed: 2", "speed: fast"), 11, "must be a number"),
    ("vector length", GOOD.replace("center: [5, 0, 2]", "center: [5, 0]"), 5, "must have 3 numbers"),
    ("negative size", GOOD.replace("size: [2, 2, 4]", "size: [2, -2, 4]"), 5, "must be positive"),
    ("zero radius", GOOD.replace("radius: 1,", "radius: 0,"), 6, "must be positive"),
    ("marker id too big", GOOD.replace("id: 7", "id: 1024"), 8, "between 0 and 1023"),
    ("marker id not integer", GOOD.replace("id: 7", "id: 7.5"), 8, "must be an integer"),
    ("duplicate name", GOOD.replace("name: red_ball", "name: post"), 10,
     "duplicate name 'post' (first used on line 6)"),
    ("duplicate marker id", GOOD.replace("markers:\n", "markers:\n  - {id: 7, position: [0, 0, 1]}\n"), 9,
     "duplicate marker id 7"),
    ("duplicate key", GOOD.replace("speed: 2,", "speed: 2, speed: 3,"), 11, "duplicate key 'speed'"),
    ("unknown obstacle type", GOOD.replace("type: cylinder", "type: cone"), 6, "box or cylinder, not 'cone'"),
    ("home outside bounds", GOOD.replace("min: [-10, -10, 0]", "min: [1, -10, 0]"), 3, "contain the home point"),
    ("inverted bounds", GOOD.replace("max: [10, 10, 10]", "max: [10, 10, -1]"), 3, "max z"),
    ("latitude", GOOD.replace("lat: 47.397742", "lat: 147.4"), 2, "home lat must be at most 90"),
    ("missing home", GOOD.replace("home: {lat: 47.397742, lon: 8.545594, alt: 488.0}\n", ""), 1,
     "misses the key 'home'"),
    ("obstacle over home", GOOD.replace("center: [5, 0, 2]", "center: [0, 0, 2]"), 5, "covers the home point"),
    ("list instead of mapping", GOOD.replace("camera: {hfov: 90, range: 8}", "camera: [90, 8]"), 12,
     "must be a mapping"),
    ("boolean loop", GOOD.replace("loop: false", "loop: 3"), 11, "true or false"),
    ("yaml syntax", GOOD.replace("objects:\n", "objects: [\n"), 10, "not valid YAML"),
]


@pytest.mark.parametrize(("text", "line", "fragment"), [b[1:] for b in BAD_WORLDS], ids=[b[0] for b in BAD_WORLDS])
def test_a_malformed_world_file_names_file_and_line(tmp_path, text, line, fragment):
    path = write(tmp_path, text)
    with pytest.raises(WorldError) as caught:
        load_world(path)
    message = str(caught.value)
    assert message.startswith(f"{path}:{line}: "), message
    assert fragment in message


def test_an_empty_or_missing_world_file_is_a_clear_error(tmp_path):
    with pytest.raises(WorldError, match=r"world.yaml:1: the world file is empty"):
        load_world(write(tmp_path, "# nothing\n"))
    with pytest.raises(WorldError, match=r"nowhere.yaml: cannot read the world file"):
        load_world(tmp_path / "nowhere.yaml")


def test_geodesy_round_trips_and_matches_the_earth_scale():
    for enu in [(0.0, 0.0, 0.0), (10.0, -20.0, 5.0), (1500.0, 2500.0, -30.0), (-0.01, 0.02, 100.0)]:
        back = geodetic_to_enu(enu_to_geodetic(enu, HOME), HOME)
        assert back == pytest.approx(enu, abs=1e-6)
    lat, lon, alt = enu_to_geodetic((0.0, 1000.0, 0.0), HOME)
    assert (lat - HOME[0]) * 111_200.0 == pytest.approx(1000.0, rel=0.01)  # ~111 km per degree of latitude
    assert lon == pytest.approx(HOME[1], abs=1e-9) and alt == pytest.approx(HOME[2], abs=0.2)
    lat, lon, _ = enu_to_geodetic((1000.0, 0.0, 0.0), HOME)
    assert (lon - HOME[1]) * 111_320.0 * math.cos(math.radians(HOME[0])) == pytest.approx(1000.0, rel=0.01)


def test_world_frame_methods_use_the_home_point():
    world = default_world()
    assert world.to_geodetic((0.0, 0.0, 0.0)) == pytest.approx(world.home)
    point = world.to_geodetic((12.0, -7.0, 3.0))
    assert world.to_enu(*point) == pytest.approx((12.0, -7.0, 3.0), abs=1e-6)


def test_the_collision_broad_phase_finds_what_the_full_scan_finds():
    import random

    from aeroexec.drones.sim.shapes import ObstacleIndex

    world = default_world()
    index = ObstacleIndex(world.obstacles, reach=0.3)
    rng = random.Random(7)
    hits = 0
    for _ in range(5000):
        point = (rng.uniform(-22, 22), rng.uniform(-22, 22), rng.uniform(-1, 12))
        for radius in (0.0, 0.3, 1.0):  # 1.0 is past the index's reach: it scans everything
            expected = world.collides(point, radius)
            assert index.collides(point, radius) is expected, (point, radius)
            hits += expected is not None
    assert hits > 100  # the points do meet obstacles


def test_a_world_file_read_without_errors_is_kept_parsed_and_a_changed_or_broken_one_is_read_again(tmp_path,
                                                                                                   monkeypatch):
    """A world is kept parsed in the user's cache folder (the next command reads no YAML for it); a changed file
    is read again, and one with errors is never kept: it is refused at its line every time."""
    from aeroexec.drones.sim import world_file

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    path = write(tmp_path, GOOD)
    first = load_world(path)
    assert [p.name.split(".")[0] for p in (tmp_path / "cache" / "aeroexec").iterdir()] == ["world"]
    monkeypatch.setattr(world_file, "_parsed", {})  # as the next command starts

    def unread(text, source="<world>"):
        raise AssertionError("parsed again")

    monkeypatch.setattr(world_file, "parse_world", unread)
    again = load_world(path)
    assert again == first and again.source == str(path) and again.obstacles == first.obstacles
    path.write_text(GOOD.replace("name: test", "name: changed"))
    with pytest.raises(AssertionError, match="parsed again"):
        load_world(path)
    monkeypatch.undo()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    assert load_world(path).name == "changed"
    broken = write(tmp_path, GOOD.replace("radius: 1", "radius: -1"), "broken.yaml")
    for _ in range(2):
        with pytest.raises(WorldError, match="broken.yaml:"):
            load_world(broken)
    assert len(list((tmp_path / "cache" / "aeroexec").glob("world.*.pickle"))) == 2  # the good file's two texts
