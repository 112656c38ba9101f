"""Arming again on a MAVLink vehicle through MAVSDK (``aeroexec sim``'s drone as PX4 and as ArduPilot): after a
landing an ArduCopter stays in LAND, and MAVSDK's arm would switch it to Hold, which is BRAKE, where ArduCopter
refuses to arm (``Arm: Brake mode not armable``); aeroexec sets GUIDED first, so a second run on the same vehicle and
a battery-swap resume take off and fly again. Holds are in LOITER, the mode docs/real-vehicles.md names."""

from __future__ import annotations

import math
import threading
import time

import pytest
from aeroexec.drones.interface import LandedState
from aeroexec.drones.mavsdk import MavsdkDrone
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from aeroexec.flight.ending import end_flight
from aeroexec.flight.journal.resume_point import resume_point
from aeroexec.flight.run_status import SUSPENDED
from free_ports import free_udp_port
from journeys import MISSIONS, achieved, active, crash, fly, fly_until, resume, spec
from patience import hang_guard

pytestmark = pytest.mark.mavsdk

SPEED = 6.0  # simulated seconds per wall second


@pytest.fixture(params=["px4", "ardupilot"])
def vehicle(request):
    port = free_udp_port()
    simulated = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=SPEED,
                               autopilot=request.param)
    simulated.start()
    try:
        yield simulated, f"mavsdk:udpin://127.0.0.1:{port}"
    finally:
        simulated.stop()


def test_a_second_run_on_the_same_vehicle_arms_takes_off_and_completes(vehicle, tmp_path):
    simulated, drone = vehicle
    for n in (1, 2):
        session, outcome = fly(spec(MISSIONS / "figure10.py", tmp_path / f"run{n}", drone=drone, ready_timeout=60.0))
        assert outcome.exit_status == 0, (n, outcome.status, outcome.faults)
        assert [b for b, _ in achieved(tmp_path / f"run{n}")] == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
        end = simulated.telemetry()
        assert end.landed_state == LandedState.ON_GROUND and not end.armed
        if simulated.copter is not None:
            assert simulated.copter.mode == "LAND"  # where ArduCopter stays after a landing: not armable


def test_a_battery_swap_resume_arms_and_flies_again(vehicle, tmp_path):
    simulated, drone = vehicle
    folder = tmp_path / "run"
    # suspended early in the first leg: at SPEED a leg lasts ~0.5 s of wall time, and under load one was seen to
    # end in 0.48 s, so a crash point 0.5 s into it never came
    run = fly_until(spec(MISSIONS / "figure10.py", folder, drone=drone, ready_timeout=60.0),
                    active("GO_TO_POINT", 0.1))
    ticket = run.engine.supervisor.submit("suspend", origin="ctl")
    if not run.engine.run_until(lambda: run.mission_done, 600):
        run.time_limit()
    outcome = run.finish(end_flight(run.engine, link_grace=run.spec.link_grace))
    assert ticket.result.ok and outcome.exit_status == 5 and outcome.status.word == SUSPENDED
    landed = simulated.telemetry()
    assert landed.landed_state == LandedState.ON_GROUND and not landed.armed  # the swap happens on the ground
    session, outcome = resume(folder, ready_timeout=60.0)
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    rejoin = [e.behavior for e in session.engine.log.events() if e.kind == "GOAL_ACHIEVED"
              and e.data.get("source") == "resume"]
    assert rejoin[:1] == ["TAKE_OFF"]  # it armed and took off again
    assert [b for b, _ in achieved(folder)][-1] == "LAND"


def test_an_ardupilot_holds_in_loiter_as_the_docs_say(tmp_path):
    port = free_udp_port()
    simulated = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=SPEED,
                               autopilot="ardupilot")
    simulated.start()
    drone = MavsdkDrone(f"udpin://127.0.0.1:{port}", ready_timeout=60.0)
    try:
        assert drone.wait_ready(60.0), drone.not_ready_because()
        assert drone.takeoff(3.0).wait(60.0)
        hold = drone.hold()
        assert hold.wait(60.0) and hold.ok, hold
        assert simulated.copter.mode == "LOITER"  # not BRAKE, MAVSDK's own hold on ArduCopter
        assert drone.telemetry().flight_mode == "LOITER"
    finally:
        drone.close()
        simulated.stop()


LEG = """<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4" main_tree_to_execute="Leg">
  <BehaviorTree ID="Leg">
    <Sequence>
      <TAKE_OFF ALTITUDE="3"/>
      <GO_TO_POINT COORDINATES="19, -19, 3"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""
TARGET = (19.0, -19.0, 3.0)
LEG_SPEED = 2.0  # simulated seconds per wall second: the 27 m leg takes 2.7 s of wall time, the crash comes mid-leg


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_a_resume_after_kill_9_mid_leg_flies_on_toward_the_target_from_where_the_drone_is(autopilot, tmp_path):
    port = free_udp_port()
    simulated = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=LEG_SPEED,
                               autopilot=autopilot)
    simulated.start()
    try:
        _kill_mid_leg_and_resume(simulated, f"mavsdk:udpin://127.0.0.1:{port}", tmp_path)
    finally:
        simulated.stop()


def _kill_mid_leg_and_resume(simulated, drone, tmp_path) -> None:
    mission = tmp_path / "leg.xml"
    mission.write_text(LEG)
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder, drone=drone, ready_timeout=60.0), active("GO_TO_POINT", 0.3)))
    seen = resume_point(folder).place  # where the journal last saw the drone, mid-leg
    assert math.dist(seen, TARGET) > 5.0
    # the autopilot flies on to the interrupted target without its companion (ArduCopter's GUIDED go-to, PX4's
    # reposition): said here, so the vehicle is there whatever the link's loss did to it meanwhile
    simulated.drone.goto(TARGET)
    deadline = time.monotonic() + hang_guard(30.0)
    while math.dist(simulated.telemetry().position, TARGET) > 1.0:
        assert time.monotonic() < deadline, "the vehicle did not fly on after the crash"
        time.sleep(0.02)
    samples: list[tuple[float, float, float]] = []
    stop = threading.Event()

    def look() -> None:
        while not stop.wait(0.02):
            samples.append(simulated.telemetry().position)

    start = math.dist(simulated.telemetry().position, TARGET)
    watcher = threading.Thread(target=look, daemon=True)
    watcher.start()
    try:
        session, outcome = resume(folder, ready_timeout=60.0)
    finally:
        stop.set()
        watcher.join()
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    events = session.engine.log.events()
    assert not [e for e in events if e.kind == "activated" and e.data.get("source") == "resume"]  # no flight back
    assert any(e.kind == "rejoin" and "goes on toward its target" in e.detail for e in events)
    flown = [p for p in samples if p[2] > 1.0]  # until the landing
    assert max(math.dist(p, TARGET) for p in flown) < max(start, 1.0) + 1.0  # never back toward the leg's start
    assert [b for b, _ in achieved(folder)] == ["TAKE_OFF", "GO_TO_POINT", "LAND"]
