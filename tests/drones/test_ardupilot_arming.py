"""ArduCopter's arming as ``aeroexec sim --autopilot ardupilot`` answers it to a plain pymavlink client: a mode that
does not allow arming (BRAKE, LAND, RTL...) refuses with ArduCopter's words; GUIDED and LOITER arm."""

from __future__ import annotations

import time

import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from patience import hang_guard
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mavlink

pytestmark = pytest.mark.mavsdk

TIMEOUT = 5.0  # s, wall: every wait below is bounded by it (stretched on a loaded machine)
CUSTOM = mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
BRAKE, LAND, GUIDED, LOITER = 17, 9, 4, 5  # Copter mode numbers (ArduCopter/mode.h)


@pytest.fixture
def copter():
    client = mavutil.mavlink_connection("udpin:127.0.0.1:0", source_system=255, source_component=190)
    port = client.port.getsockname()[1]
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=4.0,
                             autopilot="ardupilot", ekf=(0.5, 1.0))
    vehicle.start()
    try:
        wait_for(client, "HEARTBEAT")
        client.mav.request_data_stream_send(1, 1, mavlink.MAV_DATA_STREAM_ALL, 5, 1)
        wait_for(client, "HOME_POSITION")  # the EKF has its origin: navigating modes may be entered
        yield client, vehicle
    finally:
        vehicle.stop()
        client.close()


def wait_for(client, kind: str, predicate=lambda m: True):
    deadline = time.monotonic() + hang_guard(TIMEOUT)
    while time.monotonic() < deadline:
        msg = client.recv_match(type=kind, blocking=True, timeout=0.1)
        if msg is not None and predicate(msg):
            return msg
    pytest.fail(f"no {kind} matching the condition within {TIMEOUT} s")


def command(client, cmd: int, *params: float, texts: list | None = None) -> int:
    p = list(params) + [0.0] * (7 - len(params))
    client.mav.command_long_send(1, 1, cmd, 0, *p)
    deadline = time.monotonic() + hang_guard(TIMEOUT)
    while time.monotonic() < deadline:
        msg = client.recv_match(type=["COMMAND_ACK", "STATUSTEXT"], blocking=True, timeout=0.1)
        if msg is None:
            continue
        if msg.get_type() == "STATUSTEXT":
            if texts is not None:
                texts.append(msg.text)
        elif msg.command == cmd and msg.result != mavlink.MAV_RESULT_IN_PROGRESS:
            return msg.result
    pytest.fail(f"no final COMMAND_ACK for command {cmd} within {TIMEOUT} s")


@pytest.mark.parametrize(("mode", "words"), [(BRAKE, "Arm: Brake mode not armable"),
                                             (LAND, "Arm: Land mode not armable")])
def test_arducopter_refuses_to_arm_in_a_mode_that_does_not_allow_it(copter, mode, words):
    client, vehicle = copter
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, CUSTOM, mode) == mavlink.MAV_RESULT_ACCEPTED
    texts: list[str] = []
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1, texts=texts) == mavlink.MAV_RESULT_FAILED
    assert words in texts, texts
    assert not vehicle.telemetry().armed


@pytest.mark.parametrize("mode", [GUIDED, LOITER])
def test_it_arms_in_guided_and_loiter(copter, mode):
    client, vehicle = copter
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, CUSTOM, BRAKE) == mavlink.MAV_RESULT_ACCEPTED
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, CUSTOM, mode) == mavlink.MAV_RESULT_ACCEPTED
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "HEARTBEAT", lambda m: m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
