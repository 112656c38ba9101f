"""Faults told truly, against ``aeroexec sim``'s ArduPilot personality over MAVSDK: a link that drops while the
vehicle gets ready, on the ground before the mission, is one warning and the run completes; events keep the
time they happened; a mission cut short by the low-battery landing ends ``suspended`` naming the battery."""

from __future__ import annotations

import time

import pytest
from aeroexec.drones.interface import LandedState
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from aeroexec.engine.events import EventLog
from aeroexec.flight.run_status import SUSPENDED, run_status
from flight_runs import MISSIONS, Command, ended, read_log
from free_ports import free_udp_port
from patience import hang_guard
from pymavlink.dialects.v20.common import MAVLINK_MSG_ID_HOME_POSITION

FIGURE10 = str(MISSIONS / "figure10.py")

pytestmark = pytest.mark.mavsdk


def wait_until(condition, timeout: float, what: str) -> None:
    deadline = time.monotonic() + hang_guard(timeout)
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"{what} did not happen within {timeout:g} s")
        time.sleep(0.05)


def test_a_link_drop_before_the_mission_is_one_warning_and_the_run_completes(tmp_path):
    port = free_udp_port()
    # the ArduCopter is not ready (no pre-arm checks passed, no home) until the drop is over: the drop is on the
    # ground before the mission whatever the machine's load; then the mission flies at 3x
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=3.0,
                             autopilot="ardupilot", ekf=(1e9, 1e9))
    vehicle.start()
    try:
        run = Command(tmp_path, "run", FIGURE10, "--plain", "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                      "--output", str(tmp_path / "out"))
        run.wait_for("waiting up to")
        # the adapter asks for the home position last, each request once the one before was answered: by then
        # it has heard the vehicle, the link is up
        wait_until(lambda: vehicle.streams.interval_us(MAVLINK_MSG_ID_HOME_POSITION) not in (None, -1),
                   60, "MAVSDK asking for the home position stream")
        assert vehicle.telemetry().landed_state == LandedState.ON_GROUND
        vehicle.cut_link()
        run.wait_for("link to the vehicle lost")
        vehicle.restore_link()
        vehicle.copter.prearm_s = vehicle.copter.origin_s = 0.0  # now it gets ready
        code, out, err = run.finish()
    finally:
        vehicle.stop()
    assert code == 0, err
    warnings = [line for line in err.splitlines() if "warning: the link to the vehicle dropped" in line]
    assert len(warnings) == 1 and "on the ground, before the mission" in warnings[0], err
    assert "figure10.py: completed" in err and "failed" not in err
    records = read_log(tmp_path / "out" / "events.jsonl")
    lost = [r for r in records if r["kind"] == "drone_link_lost"]
    started = next(r["time"] for r in records if r["kind"] == "mission_started")
    assert len(lost) == 1 and lost[0]["time"] < started  # one drop, at the time it happened: before the mission
    assert ended(records)["detail"] == "completed"


def test_a_low_battery_landing_ends_suspended_naming_the_battery(tmp_path):
    port = free_udp_port()
    # from 10.5% the run's LAND on low battery (below 10%) comes as the flight starts, and must come before the
    # vehicle's own failsafe (7%): the charge the run sees comes once a second; at 2x, with 4 minutes of hover, that
    # gap lasts 3.6 s of wall time (at 4x and 2 minutes, 0.9 s: on a loaded machine the failsafe landed first)
    drone = SimulatedDrone(config=SimConfig(initial_battery_percent=10.5, battery_hover_minutes=4.0))
    vehicle = MavlinkVehicle(drone, connect=f"udpout://127.0.0.1:{port}", speed=2.0, autopilot="ardupilot")
    vehicle.start()
    try:
        run = Command(tmp_path, "run", FIGURE10, "--plain", "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                      "--output", str(tmp_path / "out"))
        code, out, err = run.finish()
        ground = vehicle.telemetry()
    finally:
        vehicle.stop()
    assert code == 5, err
    assert "figure10.py: suspended at t=" in err and "LAND on low battery at t=" in err, err
    assert ground.landed_state == LandedState.ON_GROUND
    status = ended(read_log(tmp_path / "out" / "events.jsonl"))
    assert status["detail"] == SUSPENDED and "LAND on low battery" in status["data"]["reasons"][0]


def test_a_reaction_after_the_mission_completed_does_not_suspend_it():
    log = EventLog(lambda: 0.0)
    log.record("mission_started")
    log.record("mission_completed")
    log.record("reactive", "LAND", "activated by reaction (higher priority): charge(battery, ?X), less_than(?X, 10)")
    assert run_status(log.events()).word == "completed"
