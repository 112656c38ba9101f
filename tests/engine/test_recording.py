"""Data recording, configuration and manipulation on the simulated drone: photos, videos and maps written to the
run's output folder, the light's state as a belief, and a dropped item leaving carry(self, X) for the world."""

import numpy as np
import pytest
from aeroexec.drones import Drone
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.drones.sim.world_file import parse_world
from aeroexec.engine.behaviors.recording import recordings
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.planning.mapping import FREE, OCCUPIED, UNKNOWN
from PIL import Image

WORLD = """
name: recording test
home: {lat: 47.397742, lon: 8.545594, alt: 488.0}
bounds: {min: [-20, -20, 0], max: [20, 20, 20]}
obstacles:
  - {name: tower, type: box, center: [8, 8, 5], size: [3, 3, 10]}
markers:
  - {id: 1, position: [8, 6.45, 2], yaw: -90}
objects:
  - {name: red_box, color: red, shape: box, position: [4, 2, 0.25]}
payload: [medkit]
"""


class NoCamera(SimulatedDrone):
    """A drone whose camera gives nothing and whose payload release is missing (like a plain adapter)."""

    def capture_image(self, width=640, height=480):
        return None

    def release_payload(self):
        return Drone.release_payload(self)


def make_engine(tmp_path, drone_class=SimulatedDrone, **extra):
    world = parse_world(WORLD, "recording-test.yaml")
    engine = Engine(drone_class(world), obstacles=world, output_dir=tmp_path)
    engine.settings.extra.update(extra)
    engine.drone.takeoff(2.0)
    engine.run_until(lambda: engine.memory.holds("flight_state(self, hovering)"), 30)
    engine.coordinator.inhibit("KEEP_HOVERING")  # the tests steer the drone directly
    return engine


@pytest.fixture
def engine(tmp_path):
    eng = make_engine(tmp_path)
    yield eng
    eng.stop()


def run(engine, name, arguments=None, seconds=0.5):
    ended = []
    result = engine.coordinator.activate(name, arguments, on_end=lambda o, m, r: ended.append((o, m, r)))
    if result.accepted:
        engine.step(seconds)
    return result, ended


def fly_to(engine, point, yaw):
    engine.drone.goto(point, yaw=yaw)

    def there():
        t = engine.drone.telemetry()
        close = max(abs(a - b) for a, b in zip(t.position, point, strict=True)) < 0.05
        return close and t.speed < 0.05 and abs(t.yaw - yaw) < 1

    assert engine.run_until(there, 30)


def test_take_photo_writes_a_png_of_the_view_and_believes_it(engine, tmp_path):
    fly_to(engine, (8.0, 0.0, 2.0), yaw=90)  # facing the tower and marker 1
    result, ended = run(engine, "TAKE_PHOTO")
    assert result.accepted and ended[0][0] is Outcome.GOAL_ACHIEVED
    path = tmp_path / "photo_1.png"
    assert ended[0][2] == str(path) and engine.memory.holds("photo(self, ?F)", {"?F": str(path)})
    image = Image.open(path)
    assert image.format == "PNG" and image.size == (640, 480)
    marker_pixels = (np.asarray(image, dtype=int).sum(axis=2) < 100).sum()
    fly_to(engine, (8.0, 0.0, 2.0), yaw=-90)
    run(engine, "TAKE_PHOTO")
    away = np.asarray(Image.open(tmp_path / "photo_2.png"), dtype=int)
    assert marker_pixels > 500 and (away.sum(axis=2) < 100).sum() == 0
    assert len(engine.memory.query_all("photo(self, ?F)")) == 2


def test_a_drone_without_camera_image_gives_wrong_progress(tmp_path):
    engine = make_engine(tmp_path, NoCamera)
    try:
        for name in ("TAKE_PHOTO", "RECORD_VIDEO"):
            _, ended = run(engine, name)
            assert ended[0][0] is Outcome.WRONG_PROGRESS and "no camera image" in ended[0][1]
        assert not list(tmp_path.iterdir())
    finally:
        engine.stop()


def test_record_video_writes_frames_while_active_and_a_gif_when_stopped(engine, tmp_path):
    result, ended = run(engine, "RECORD_VIDEO", seconds=0.1)
    assert result.accepted and "CAMERA_CONTROL_FOR_VIDEOS" in engine.resources.running()
    engine.drone.set_velocity((0.0, 0.0, 0.0), yaw_rate=30.0)
    engine.step(4.0)
    engine.coordinator.inhibit("RECORD_VIDEO")
    frames = sorted((tmp_path / "video_1").glob("frame_*.png"))
    assert 8 <= len(frames) <= 10  # 2 frames per second
    gif = Image.open(tmp_path / "video_1.gif")
    assert gif.n_frames == len(frames)
    assert ended[0][0] is Outcome.INTERRUPTED and engine.memory.holds("video(self, ?F)",
                                                                      {"?F": str(tmp_path / "video_1.gif")})
    engine.step(1.0)
    assert len(list((tmp_path / "video_1").glob("frame_*.png"))) == len(frames)  # no frame once stopped


def test_build_map_marks_the_tower_occupied_after_flying_past_it(engine, tmp_path):
    fly_to(engine, (2.0, 0.0, 2.0), yaw=-90)  # facing away from the tower
    result, _ = run(engine, "BUILD_MAP", {"DIMENSION": "THREE"})
    occupancy = recordings(engine.context).map
    assert result.accepted and occupancy.state(8.0, 6.75) == UNKNOWN
    fly_to(engine, (2.0, 0.0, 2.0), yaw=90)
    engine.drone.goto((14.0, 0.0, 2.0), yaw=90)  # east along the tower's south side, looking north
    engine.run_until(lambda: engine.drone.telemetry().position[0] > 13.5, 30)
    engine.coordinator.inhibit("BUILD_MAP")
    assert occupancy.state(8.0, 6.75) == OCCUPIED and occupancy.state(6.75, 7.5) == OCCUPIED
    assert occupancy.state(8.0, 3.0) == FREE  # between the path and the tower
    assert occupancy.state(-15.0, -15.0) == UNKNOWN  # never in view
    assert "marker_1" in occupancy.landmarks
    top = np.asarray(Image.open(tmp_path / "map_1.png"), dtype=int)
    i, j = int((9.0 + 20) / 0.5), int((6.75 + 20) / 0.5)  # the cell of (9, 6.75): 0.5 m cells from (-20, -20)
    row, col = (79 - j) * 4 + 2, i * 4 + 2  # 4 pixels per cell, north up
    assert top[row, col].sum() < 150  # drawn dark: occupied
    assert (tmp_path / "map_1_height.png").exists()
    assert engine.memory.holds("map(self, ?F)", {"?F": str(tmp_path / "map_1.png")})


def test_build_map_saves_periodically_and_two_dimensions_give_one_image(tmp_path):
    engine = make_engine(tmp_path, map_save_period=2.0)
    try:
        run(engine, "BUILD_MAP", {"DIMENSION": "TWO"}, seconds=5.0)
        assert len(engine.log.events("map_saved")) == 2  # after 2 and 4 s, while active
        assert (tmp_path / "map_1.png").exists() and not (tmp_path / "map_1_height.png").exists()
        engine.coordinator.inhibit("BUILD_MAP")
        assert len(engine.log.events("map_saved")) == 3 and not (tmp_path / "map_2.png").exists()
    finally:
        engine.stop()


def test_turn_lights_keeps_the_light_state_as_a_belief(engine):
    result, ended = run(engine, "TURN_LIGHTS", {"MODE": "ON"})
    assert result.accepted and ended[0][0] is Outcome.GOAL_ACHIEVED
    assert engine.memory.holds("light(self, on)")
    again, _ = run(engine, "TURN_LIGHTS", {"MODE": "ON"})
    assert not again.accepted and again.outcome is Outcome.GOAL_ACHIEVED and "already on" in again.message
    run(engine, "TURN_LIGHTS", {"MODE": "OFF"})
    assert engine.memory.holds("light(self, off)") and not engine.memory.holds("light(self, on)")
    errors = engine.specialist.check_plan([("TURN_LIGHTS", {"MODE": "ON"}), ("TURN_LIGHTS", {"MODE": "ON"})])
    assert [(e.kind, e.step) for e in errors] == [("WRONG_SEQUENCE", 1)]


def test_drop_item_retracts_carry_and_the_item_lands_below(engine):
    assert engine.memory.holds("carry(self, medkit)")
    fly_to(engine, (2.0, -3.0, 2.0), yaw=0)
    result, ended = run(engine, "DROP_ITEM", seconds=2.0)
    assert result.accepted and ended[0][0] is Outcome.GOAL_ACHIEVED and ended[0][2] == "medkit"
    assert not engine.memory.holds("carry(self, ?X)")
    medkit = next(o for o in engine.drone.world.objects if o.name == "medkit")
    assert medkit.position == pytest.approx((2.0, -3.0, 0.15), abs=0.1)
    again, _ = run(engine, "DROP_ITEM")
    assert not again.accepted and again.outcome is Outcome.FAILED_PRECONDITIONS
    assert not engine.memory.holds("carry(self, ?X)")  # the updater does not bring it back


def test_drop_item_without_a_payload_release_gives_the_drones_reason(tmp_path):
    engine = make_engine(tmp_path, NoCamera)
    try:
        engine.memory.add("carry(self, rope)")
        _, ended = run(engine, "DROP_ITEM")
        assert ended[0][0] is Outcome.WRONG_PROGRESS and "no payload release" in ended[0][1]
        assert engine.memory.holds("carry(self, rope)")
    finally:
        engine.stop()


def test_the_default_output_folder_is_under_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    world = parse_world(WORLD, "recording-test.yaml")
    engine = Engine(SimulatedDrone(world, config=SimConfig(payload=())), obstacles=world)
    try:
        _, ended = run(engine, "TAKE_PHOTO")
        photo = tmp_path / ended[0][2]  # relative to the working directory
        assert ended[0][0] is Outcome.GOAL_ACHIEVED and ended[0][2].startswith("aeroexec_output")
        assert photo.parent.parent == tmp_path / "aeroexec_output" and Image.open(photo).format == "PNG"
    finally:
        engine.stop()
