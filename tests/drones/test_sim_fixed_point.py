"""A vehicle hovering on its target skips its control laws (their fixed point: no turn, no velocity asked), and in
calm air with nothing to touch, a period's substeps move only its clock and battery: the flight is the same, bit for
bit, as with the control laws and every check run at every substep."""

import importlib.util
from pathlib import Path

import aeroexec.drones.sim.drone as drone_module
import aeroexec.drones.sim.vehicle as vehicle_package
import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.drones.sim.shapes import Box
from aeroexec.drones.sim.vehicle.multicopter import Multicopter
from aeroexec.drones.sim.world import Bounds, Platform, World, WorldObject

HOME = (47.397742, 8.545594, 488.0)


def source_multicopter() -> type:
    """``Multicopter`` as ``multicopter.py`` writes it, loaded from the source: the class the compiled build
    (``tools/build-compiled``) replaces, when it is built, by its extension's, whose methods cannot be replaced."""
    path = Path(next(iter(vehicle_package.__path__))) / "multicopter.py"
    spec = importlib.util.spec_from_file_location("aeroexec.drones.sim.vehicle._multicopter_source", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.Multicopter


def world(platform: bool, crate: bool = True) -> World:
    """A field with a building, if asked a thing to touch and a moving platform: every check a substep makes."""
    return World(home=HOME, bounds=Bounds((-60.0, -60.0, 0.0), (60.0, 60.0, 30.0)),
                 obstacles=(Box("shed", (20.0, 20.0, 0.0), (24.0, 24.0, 5.0)),),
                 objects=(WorldObject("crate", "red", "box", (3.0, 0.0, 3.0)),) if crate else (),
                 platform=Platform("deck", path=((-10.0, -10.0, 1.0), (-10.0, 10.0, 1.0)), speed=0.5)
                 if platform else None)


def fly(config: SimConfig, platform: bool, crate: bool) -> list[tuple]:
    """Take off, hold still, turn to a heading and hold, fly over the crate and hold, land: every telemetry."""
    drone = SimulatedDrone(world(platform, crate), config=config, seed=3)
    seen: list[tuple] = []
    plan = {1: lambda: drone.arm(), 2: lambda: drone.takeoff(3.0), 300: lambda: drone.goto((0.0, 0.0, 3.0), yaw=190.0),
            500: lambda: drone.goto((3.0, 0.0, 3.0)), 800: lambda: drone.land()}
    for i in range(1, 1100):
        if i in plan:
            plan[i]()
        drone.update(i * 0.05)
        t = drone.telemetry()
        v = drone._vehicle  # and what the vehicle keeps for its next substeps
        seen.append((t.position, t.velocity, t.yaw, t.battery_percent, t.landed_state, t.flight_mode,
                     [(e.kind, e.detail) for e in drone.events()],
                     (v.time, v.phase, v.yaw_rate, v.failsafe, v.crashed, v._flew_since_armed, v._outside)))
    return seen


# 0.83 % per second: at 7 % (the failsafe) or empty in the first hover (at rest from 8.4 s)
LOW = {"initial_battery_percent": 16.0, "battery_hover_minutes": 2.0}
EMPTY = {"initial_battery_percent": 11.0, "battery_hover_minutes": 2.0, "failsafe_battery_percent": 0.0}


@pytest.mark.parametrize("config, platform, crate", [
    (SimConfig(), False, True),
    (SimConfig(), True, True),
    (SimConfig(), False, False),
    (SimConfig(wind=(1.5, -0.5), wind_gust=0.8), False, False),
    (SimConfig(position_noise_std=0.05), False, False),
    (SimConfig(**LOW), False, False),
    (SimConfig(**EMPTY), False, False),
], ids=["calm", "platform", "nothing-to-touch", "wind", "noise", "failsafe", "empty-battery"])
def test_a_hover_skipping_the_control_laws_flies_as_running_them(config, platform, crate, monkeypatch):
    held = []
    source = source_multicopter()  # its methods counted and replaced below
    monkeypatch.setattr(drone_module, "Multicopter", source)
    on_target, hold_still = source._on_target, source.hold_still

    def counted(self):
        still = on_target(self)
        held.append(still)
        return still

    def holding(self, *args):
        held.append("held")
        return hold_still(self, *args)

    monkeypatch.setattr(source, "_on_target", counted)
    monkeypatch.setattr(source, "hold_still", holding)
    fast = fly(config, platform, crate)
    monkeypatch.setattr(source, "_on_target", lambda self: False)  # the control laws at every substep
    assert repr(fly(config, platform, crate)) == repr(fast)  # bit for bit: -0.0 is not 0.0 in a log
    assert any(h is True for h in held), "the flight never held still on its target: the test tests nothing"
    if not crate and not config.wind:  # nothing to touch in calm air: whole substeps skipped too
        assert "held" in held


@pytest.mark.parametrize("config, platform, crate", [
    (SimConfig(), True, True),
    (SimConfig(wind=(1.5, -0.5), wind_gust=0.8), False, False),
    (SimConfig(**LOW), False, False),
], ids=["platform", "wind", "failsafe"])
def test_the_vehicle_imported_flies_as_its_source(config, platform, crate, monkeypatch):
    """The compiled build's vehicle (when built; else the source, imported) flies the source's flight, bit for bit."""
    imported = fly(config, platform, crate)
    monkeypatch.setattr(drone_module, "Multicopter", source_multicopter())
    assert drone_module.Multicopter is not Multicopter
    assert repr(fly(config, platform, crate)) == repr(imported)
