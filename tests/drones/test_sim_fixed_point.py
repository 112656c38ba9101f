"""A vehicle hovering on its target skips its control laws (their fixed point: no turn, no velocity asked): the
flight is the same, bit for bit, as with the control laws run at every substep."""

import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.drones.sim.shapes import Box
from aeroexec.drones.sim.vehicle.multicopter import Multicopter
from aeroexec.drones.sim.world import Bounds, Platform, World, WorldObject

HOME = (47.397742, 8.545594, 488.0)


def world(platform: bool) -> World:
    """A field with a building, a thing to touch and, if asked, a moving platform: every check a substep makes."""
    return World(home=HOME, bounds=Bounds((-60.0, -60.0, 0.0), (60.0, 60.0, 30.0)),
                 obstacles=(Box("shed", (20.0, 20.0, 0.0), (24.0, 24.0, 5.0)),),
                 objects=(WorldObject("crate", "red", "box", (3.0, 0.0, 3.0)),),
                 platform=Platform("deck", path=((-10.0, -10.0, 1.0), (-10.0, 10.0, 1.0)), speed=0.5)
                 if platform else None)


def fly(config: SimConfig, platform: bool) -> list[tuple]:
    """Take off, hold still, turn to a heading and hold, fly over the crate and hold, land: every telemetry."""
    drone = SimulatedDrone(world(platform), config=config, seed=3)
    seen: list[tuple] = []
    plan = {1: lambda: drone.arm(), 2: lambda: drone.takeoff(3.0), 300: lambda: drone.goto((0.0, 0.0, 3.0), yaw=190.0),
            500: lambda: drone.goto((3.0, 0.0, 3.0)), 800: lambda: drone.land()}
    for i in range(1, 1100):
        if i in plan:
            plan[i]()
        drone.update(i * 0.05)
        t = drone.telemetry()
        seen.append((t.position, t.velocity, t.yaw, t.battery_percent, t.landed_state, t.flight_mode,
                     [(e.kind, e.detail) for e in drone.events()]))
    return seen


@pytest.mark.parametrize("config, platform", [
    (SimConfig(), False),
    (SimConfig(), True),
    (SimConfig(wind=(1.5, -0.5), wind_gust=0.8), False),
    (SimConfig(position_noise_std=0.05), True),
], ids=["calm", "platform", "wind", "noise"])
def test_a_hover_skipping_the_control_laws_flies_as_running_them(config, platform, monkeypatch):
    skipped = []
    on_target = Multicopter._on_target

    def counted(self):
        held = on_target(self)
        skipped.append(held)
        return held

    monkeypatch.setattr(Multicopter, "_on_target", counted)
    fast = fly(config, platform)
    monkeypatch.setattr(Multicopter, "_on_target", lambda self: False)  # the control laws at every substep
    assert repr(fly(config, platform)) == repr(fast)  # bit for bit: -0.0 is not 0.0 in a log
    assert any(skipped), "the flight never held still on its target: the test tests nothing"
