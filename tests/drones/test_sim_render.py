"""Simulated camera images and the payload: what the camera sees is drawn, what the drone drops lands in the world."""

import io

import numpy as np
import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.drones.sim.camera import Camera
from aeroexec.drones.sim.payload import surface_below
from aeroexec.drones.sim.render import COLORS, SceneRenderer
from aeroexec.drones.sim.topview import render_map
from aeroexec.drones.sim.world import WorldError
from aeroexec.drones.sim.world_file import parse_world
from PIL import Image

WORLD = """
name: render test
home: {lat: 47.397742, lon: 8.545594, alt: 488.0}
bounds: {min: [-20, -20, 0], max: [20, 20, 20]}
obstacles:
  - {name: tower, type: box, center: [8, 8, 5], size: [3, 3, 10]}
  - {name: tree, type: cylinder, center: [-10, -6], radius: 1.0, height: 8}
markers:
  - {id: 1, position: [8, 6.45, 2], yaw: -90}
objects:
  - {name: red_box, color: red, shape: box, position: [4, 2, 0.25]}
  - {name: blue_ball, color: blue, shape: sphere, position: [8, 11, 0.2]}
platform: {name: rover, path: [[-6, -14, 0.5], [6, -14, 0.5]], speed: 1.0, marker_id: 42}
payload: [medkit, water]
"""


@pytest.fixture(scope="module")
def world():
    return parse_world(WORLD, "render-test.yaml")


def view(world, position, yaw, time=0.0, size=(320, 240)):
    image = SceneRenderer(world).render(position, yaw, Camera.from_settings(world.camera), time, *size)
    return np.asarray(image, dtype=int)


def near(pixels, rgb, tolerance=40):
    return int((np.abs(pixels - np.array(rgb)).sum(axis=2) < tolerance).sum())


def dark(pixels):
    return int((pixels.sum(axis=2) < 100).sum())


def test_capture_image_is_a_png_of_the_requested_size(world):
    drone = SimulatedDrone(world)
    png = drone.capture_image(width=320, height=240)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    image = Image.open(io.BytesIO(png))
    assert image.size == (320, 240) and image.mode == "RGB"
    assert Image.open(io.BytesIO(drone.capture_image())).size == (640, 480)  # the default


def test_a_marker_in_view_shows_its_black_square(world):
    facing = view(world, (8.0, 0.0, 2.0), 90.0)  # facing north: the tower's south face and marker 1
    away = view(world, (8.0, 0.0, 2.0), -90.0)
    assert dark(facing) > 200 and dark(away) == 0
    assert near(facing[60:180, 100:220], (170, 165, 155), 120) > 2000  # the tower fills the middle
    assert dark(view(world, (8.0, 0.0, 2.0), 90.0, size=(640, 480))) > 4 * 200  # scales with the image


def test_a_marker_is_not_seen_from_behind_or_through_its_obstacle(world):
    behind = view(world, (8.0, 14.0, 2.0), -90.0)  # north of the tower, facing it: the marker is on the far side
    assert dark(behind) == 0
    assert near(behind, COLORS["blue"], 60) > 0  # the blue ball in front of the tower is drawn over it


def test_colored_objects_are_drawn_in_their_color(world):
    facing = view(world, (0.0, 0.0, 2.0), 0.0)  # facing east: the red box at (4, 2)
    away = view(world, (0.0, 0.0, 2.0), 180.0)
    assert near(facing, COLORS["red"], 90) > 100
    assert near(away, COLORS["red"], 90) == 0


def test_the_moving_platform_is_drawn_where_it_is(world):
    from aeroexec.drones.sim.render import PLATFORM_COLOR

    at_start = view(world, (-6.0, -6.0, 3.0), -90.0, time=0.0)  # above its start, facing south
    later = view(world, (-6.0, -6.0, 3.0), -90.0, time=12.0)  # it has driven 12 m east
    assert near(at_start, PLATFORM_COLOR, 60) > 50
    assert near(later, PLATFORM_COLOR, 60) < near(at_start, PLATFORM_COLOR, 60) / 4


def test_the_top_down_map_shows_the_world_and_the_trail(world):
    image = render_map(world, trail=[(0, 0, 2), (5, 0, 2), (5, 5, 2)], yaw=90.0, scale=8.0)
    assert image.size == (320, 320)
    pixels = np.asarray(image, dtype=int)
    assert near(pixels, (30, 60, 230), 30) > 20  # the trail
    assert near(pixels, (220, 30, 30), 30) > 5  # the drone
    tower = pixels[(20 - 9) * 8:(20 - 7) * 8, (20 + 7) * 8:(20 + 9) * 8]  # rows from the north
    assert tower.mean() < 140  # tall and dark


def test_payload_from_the_world_file_and_the_config(world):
    assert world.payload == ("medkit", "water")
    assert SimulatedDrone(world).payload() == ["medkit", "water"]
    assert SimulatedDrone(world, config=SimConfig(payload=("rope",))).payload() == ["rope"]
    with pytest.raises(WorldError, match="duplicate name 'tower'"):
        parse_world(WORLD.replace("payload: [medkit, water]", "payload: [tower]"))


def fly(drone, until, dt=0.05):
    t = drone.telemetry().time
    while t < until:
        t += dt
        drone.update(t)


def test_a_released_item_falls_and_lands_as_an_object_the_camera_sees(world):
    drone = SimulatedDrone(world)
    drone.takeoff(3.0)
    fly(drone, 5.0)
    drone.goto((1.0, 1.0, 3.0), yaw=0.0)
    fly(drone, 10.0)
    assert drone.release_payload().ok
    assert drone.payload() == ["water"]
    assert "medkit" not in {o.name for o in drone.world.objects}  # still falling
    fly(drone, 11.0)
    medkit = next(o for o in drone.world.objects if o.name == "medkit")
    assert medkit.position[0] == pytest.approx(1.0, abs=0.1) and medkit.position[1] == pytest.approx(1.0, abs=0.1)
    assert medkit.position[2] == pytest.approx(0.15)
    kinds = [e.kind for e in drone.events()]
    assert "payload_released" in kinds and "payload_landed" in kinds
    drone.goto((-2.0, 1.0, 3.0), yaw=0.0)  # back off, facing it
    fly(drone, 16.0)
    assert "medkit" in {o.name for o in drone.observations()}
    pixels = np.asarray(Image.open(io.BytesIO(drone.capture_image(320, 240))), dtype=int)
    assert near(pixels, COLORS["orange"], 90) > 20


def test_release_refused_when_nothing_is_carried(world):
    drone = SimulatedDrone(world, config=SimConfig(payload=()))
    handle = drone.release_payload()
    assert not handle.ok and "carries nothing" in handle.reason


def test_an_item_dropped_over_an_obstacle_lands_on_its_top(world):
    assert surface_below(world, 8.0, 8.0, 12.0) == 10.0
    assert surface_below(world, 8.0, 8.0, 5.0) == 0.0  # below the top: not that surface
    assert surface_below(world, -10.0, -6.0, 9.0) == 8.0
    assert surface_below(world, 0.0, 0.0, 5.0) == 0.0
