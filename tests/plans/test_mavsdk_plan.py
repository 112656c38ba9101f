"""A plan uploaded through MAVSDK (its own QGroundControl importer) to ``aeroexec sim --home`` at the plan's home flies
the route aeroexec flies for the same plan; MAVSDK's importer reads the real plans into the same items as ours."""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import time

import pytest
from aeroexec.cli.sim import sim_world
from aeroexec.drones.geodesy import geo_to_enu
from aeroexec.drones.interface import LandedState
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from aeroexec.trees.items.model import GLOBAL_FRAMES, POSITIONAL
from aeroexec.trees.items.readers import load_item_mission
from free_ports import free_udp_port
from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from real_missions import DATA, FILES, fly

pytestmark = pytest.mark.mavsdk

SPEED = 20.0  # simulated seconds per wall second
WAIT_S = 60.0  # s, wall: the longest any phase may take
PLAN = DATA / "idt_assignments" / "uas_center_autonomous_flight.plan"  # Odense, with hold times and a return



async def _until(check, what: str, timeout: float = WAIT_S) -> None:
    start = time.monotonic()
    while not check():
        if time.monotonic() - start > timeout:
            raise TimeoutError(f"timed out waiting for {what}")
        await asyncio.sleep(0.02)


async def _fly_through_mavsdk(url: str, vehicle: MavlinkVehicle, track: list, imported: list) -> None:
    async with Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION)) as mavsdk:
        await mavsdk.add_any_connection(url)
        system = await mavsdk.first_autopilot(timeout_s=WAIT_S)
        assert system is not None, "no autopilot heard"
        mission, action, telemetry = MissionRawAsync(system), ActionAsync(system), TelemetryAsync(system)
        for path in FILES:  # MAVSDK's own importer, for the comparison of items
            if path.suffix == ".plan":
                with contextlib.suppress(Exception):  # files MAVSDK refuses are not compared
                    imported.append((path, await mission.import_qgroundcontrol_mission(str(path))))
        plan = await mission.import_qgroundcontrol_mission(str(PLAN))
        await mission.upload_mission(plan.mission_items)
        await telemetry.set_rate_position(10.0)
        await _until(lambda: vehicle.telemetry().home is not None, "a home position")
        await action.arm()
        await mission.start_mission()

        def sample() -> bool:
            t = vehicle.telemetry()
            track.append(t.position)
            return len(track) > 50 and t.landed_state == LandedState.ON_GROUND

        await _until(sample, "the end of the mission", timeout=4 * WAIT_S)


def to_segment(point: tuple, a: tuple, b: tuple) -> float:
    """The distance from ``point`` to the segment from ``a`` to ``b``."""
    ab = [y - x for x, y in zip(a, b, strict=True)]
    length = sum(c * c for c in ab)
    t = 0.0 if length == 0 else max(0.0, min(1.0, sum((p - x) * c for p, x, c in zip(point, a, ab, strict=True))
                                                   / length))
    return math.dist(point, [x + t * c for x, c in zip(a, ab, strict=True)])


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_a_plan_uploaded_through_mavsdk_to_the_simulator_at_its_home_flies_aeroexecs_route(autopilot, tmp_path):
    status, events, world, _ = fly(PLAN, tmp_path)
    assert status.name == "SUCCESS"
    ours = [e.data["arguments"]["COORDINATES"] for e in events if e.kind == "activated" and e.behavior == "GO_TO_POINT"]
    home = json.loads(PLAN.read_text())["mission"]["plannedHomePosition"]
    port = free_udp_port()
    simulated = sim_world(None, (home[0], home[1], home[2]))  # aeroexec sim --home LAT,LON,ALT
    assert simulated.home == pytest.approx(world.home)
    vehicle = MavlinkVehicle(SimulatedDrone(simulated), connect=f"udpout://127.0.0.1:{port}", speed=SPEED,
                             autopilot=autopilot)
    vehicle.start()
    track: list = []
    imported: list = []
    try:
        asyncio.run(_fly_through_mavsdk(f"udpin://127.0.0.1:{port}", vehicle, track, imported))
    finally:
        vehicle.stop()
    assert len(ours) >= 4
    start = 0
    for point in ours:  # every point aeroexec flew to, visited in the same order by the MAVSDK mission: the track
        # is the line through the positions sampled (sparse on a loaded machine: it flew straight between them)
        nearest = min(range(start, len(track) - 1), key=lambda i: to_segment(point, track[i], track[i + 1]))
        assert to_segment(point, track[nearest], track[nearest + 1]) < 2.5, \
            (point, track[nearest], track[nearest + 1])  # NAV_ACC_RAD is 2 m
        start = nearest
    assert math.dist(track[-1][:2], (0.0, 0.0)) < 1.0  # back home: the plan's RTL
    compared = 0
    for path, data in imported:  # MAVSDK's importer and ours read the same items from the same files
        ours_items = [i for i in load_item_mission(path).items]
        theirs = [i for i in data.mission_items]
        if theirs and autopilot == "ardupilot":
            theirs = theirs[1:]  # MAVSDK puts home in front of an ArduPilot mission
        if len(theirs) != len(ours_items):
            continue  # MAVSDK leaves out what it does not import (e.g. a structure scan)
        for mine, item in zip(ours_items, theirs, strict=True):
            assert mine.command == item.command
            if mine.command in POSITIONAL and mine.frame in GLOBAL_FRAMES and mine.has_position():
                assert (mine.latitude, mine.longitude) == pytest.approx((item.x * 1e-7, item.y * 1e-7), abs=2e-7)
                assert mine.altitude == pytest.approx(item.z, abs=0.01, nan_ok=True)
        compared += 1
    assert compared >= 5
    first = geo_to_enu((json.loads(PLAN.read_text())["mission"]["items"][1]["params"][4],
                        json.loads(PLAN.read_text())["mission"]["items"][1]["params"][5], 30.0), world.home)
    assert math.dist(ours[0], first) < 0.05
