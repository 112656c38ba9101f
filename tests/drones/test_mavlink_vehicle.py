"""The MAVLink simulated vehicle seen by a plain pymavlink client on loopback: what a PX4 would answer."""

from __future__ import annotations

import math
import time

import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.drones.sim.mavlink.telemetry import px4_custom_mode
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle, MavlinkVehicleError, normalize_url
from patience import hang_guard
from pymavlink import mavutil
from pymavlink.dialects.v20 import ardupilotmega
from pymavlink.dialects.v20 import common as mavlink

pytestmark = pytest.mark.mavsdk

TIMEOUT = 5.0  # s, wall: every wait below is bounded by it


@pytest.fixture
def link():
    """A pymavlink client listening on a free loopback port, and the vehicle (10x real time) talking to it."""
    client = mavutil.mavlink_connection("udpin:127.0.0.1:0", source_system=255, source_component=190)
    port = client.port.getsockname()[1]
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=10.0)
    vehicle.start()
    try:
        wait_for(client, "HEARTBEAT")
        yield client, vehicle
    finally:
        vehicle.stop()
        client.close()


def wait_for(client, kind: str, predicate=lambda m: True, timeout: float = TIMEOUT):
    """The first ``kind`` message satisfying ``predicate``; fails the test after ``timeout`` seconds (stretched on a
    loaded machine)."""
    deadline = time.monotonic() + hang_guard(timeout)
    while time.monotonic() < deadline:
        msg = client.recv_match(type=kind, blocking=True, timeout=0.1)
        if msg is not None and predicate(msg):
            return msg
    pytest.fail(f"no {kind} matching the condition within {timeout} s")


def command(client, cmd: int, *params: float, texts: list | None = None) -> int:
    """Send a COMMAND_LONG and return the final COMMAND_ACK result; STATUSTEXTs before it go to ``texts``."""
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


def test_heartbeat_is_a_px4_quadrotor_in_its_simulated_mode_and_disarmed(link):
    client, vehicle = link
    hb = wait_for(client, "HEARTBEAT")
    assert hb.autopilot == mavlink.MAV_AUTOPILOT_PX4
    assert hb.type == mavlink.MAV_TYPE_QUADROTOR
    assert hb.base_mode & mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    assert not hb.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED
    assert hb.custom_mode == px4_custom_mode(vehicle.telemetry().flight_mode)
    assert hb.custom_mode != px4_custom_mode("OFFBOARD")
    status = wait_for(client, "SYS_STATUS")
    assert status.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_PREARM_CHECK  # armable
    assert status.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_SENSOR_GPS
    home = wait_for(client, "HOME_POSITION")
    pos = wait_for(client, "GLOBAL_POSITION_INT")
    assert (pos.lat, pos.lon) == (home.latitude, home.longitude)
    assert abs(pos.relative_alt) < 100  # mm: on the ground at home


def test_arm_is_acknowledged_and_an_extra_heartbeat_tells_it_at_once(link):
    client, _ = link
    wait_for(client, "HEARTBEAT")  # the periodic one; the next comes in a second unless something changes
    sent = time.monotonic()
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "HEARTBEAT", lambda m: m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
    assert time.monotonic() - sent < 0.5
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 0) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "HEARTBEAT", lambda m: not m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED)


def test_takeoff_climbs_to_the_takeoff_altitude_parameter_and_reports_in_air(link):
    client, _ = link
    client.mav.param_set_send(1, 1, b"MIS_TAKEOFF_ALT", 3.0, mavlink.MAV_PARAM_TYPE_REAL32)
    wait_for(client, "PARAM_VALUE", lambda m: m.param_id == "MIS_TAKEOFF_ALT" and m.param_value == 3.0)
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1) == mavlink.MAV_RESULT_ACCEPTED
    nan = math.nan
    assert command(client, mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, nan, nan, nan, nan) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "EXTENDED_SYS_STATE", lambda m: m.landed_state == mavlink.MAV_LANDED_STATE_IN_AIR, timeout=10)
    pos = wait_for(client, "GLOBAL_POSITION_INT", lambda m: m.relative_alt > 2800, timeout=10)
    assert pos.relative_alt < 3300
    local = wait_for(client, "LOCAL_POSITION_NED")
    assert local.z == pytest.approx(-3.0, abs=0.3)  # NED: up is negative z


def test_refused_commands_are_denied_with_a_statustext_saying_why(link):
    client, _ = link
    texts: list[str] = []
    nan = math.nan
    # A take-off to an AMSL altitude below home, a reposition on the ground: the simulated state decides.
    result = command(client, mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, nan, nan, nan, -5.0, texts=texts)
    assert result == mavlink.MAV_RESULT_DENIED
    assert any("takeoff" in t.lower() for t in texts), texts
    texts.clear()
    assert command(client, mavlink.MAV_CMD_DO_REPOSITION, -1, 0, 0, nan, nan, nan, nan, texts=texts) in (
        mavlink.MAV_RESULT_DENIED,
        mavlink.MAV_RESULT_FAILED,
    )
    assert texts
    assert command(client, 31337) == mavlink.MAV_RESULT_UNSUPPORTED


def test_a_low_battery_fails_the_pre_arm_check_and_arming_is_denied():
    client = mavutil.mavlink_connection("udpin:127.0.0.1:0", source_system=255, source_component=190)
    port = client.port.getsockname()[1]
    drone = SimulatedDrone(config=SimConfig(initial_battery_percent=5.0))
    vehicle = MavlinkVehicle(drone, connect=f"udpout://127.0.0.1:{port}", speed=10.0)
    vehicle.start()
    try:
        status = wait_for(client, "SYS_STATUS")
        assert status.onboard_control_sensors_present & mavlink.MAV_SYS_STATUS_PREARM_CHECK
        assert not status.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_PREARM_CHECK
        texts: list[str] = []
        assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1, texts=texts) == mavlink.MAV_RESULT_DENIED
        assert any("battery" in t for t in texts), texts
    finally:
        vehicle.stop()
        client.close()


def test_parameters_read_set_and_list(link):
    client, _ = link
    client.mav.param_request_read_send(1, 1, b"MIS_TAKEOFF_ALT", -1)
    value = wait_for(client, "PARAM_VALUE", lambda m: m.param_id == "MIS_TAKEOFF_ALT")
    assert value.param_type == mavlink.MAV_PARAM_TYPE_REAL32
    client.mav.param_set_send(1, 1, b"MIS_TAKEOFF_ALT", 7.5, mavlink.MAV_PARAM_TYPE_REAL32)
    assert wait_for(client, "PARAM_VALUE", lambda m: m.param_id == "MIS_TAKEOFF_ALT").param_value == 7.5
    client.mav.param_set_send(1, 1, b"MIS_TAKEOFF_ALT", 500.0, mavlink.MAV_PARAM_TYPE_REAL32)  # out of range
    assert wait_for(client, "PARAM_VALUE", lambda m: m.param_id == "MIS_TAKEOFF_ALT").param_value == 7.5
    client.mav.param_request_list_send(1, 1)
    first = wait_for(client, "PARAM_VALUE")
    names = {first.param_id}
    while len(names) < first.param_count:
        names.add(wait_for(client, "PARAM_VALUE").param_id)
    assert {"MIS_TAKEOFF_ALT", "MPC_XY_CRUISE", "NAV_ACC_RAD", "MAV_SYS_ID"} <= names


def test_message_interval_changes_a_stream_and_request_message_sends_one(link):
    client, _ = link
    attitude = mavlink.MAVLINK_MSG_ID_ATTITUDE
    assert command(client, mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, attitude, 20_000) == mavlink.MAV_RESULT_ACCEPTED
    assert rate_against(client, "ATTITUDE", "GLOBAL_POSITION_INT") >= 2.5  # 50 Hz asked, 10 Hz (as the other) before
    assert command(client, mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, attitude, -1) == mavlink.MAV_RESULT_ACCEPTED
    assert not arrive_before(client, "ATTITUDE", "GLOBAL_POSITION_INT", 3)  # stopped: three of the other, none of it
    assert command(client, mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, 9999, 1000) == mavlink.MAV_RESULT_UNSUPPORTED
    version = mavlink.MAVLINK_MSG_ID_AUTOPILOT_VERSION
    assert command(client, mavlink.MAV_CMD_REQUEST_MESSAGE, version) == mavlink.MAV_RESULT_ACCEPTED
    reply = wait_for(client, "AUTOPILOT_VERSION")
    assert reply.capabilities & mavlink.MAV_PROTOCOL_CAPABILITY_MISSION_INT


def rate_against(client, kind: str, other: str, n: int = 20) -> float:
    """How many ``kind`` messages came per ``other`` message (a stream at its default rate) until ``n`` of ``kind``
    came: a rate measured against the vehicle's own clock of streams, not against the wall (a loaded machine delays
    both alike)."""
    counts = {kind: 0, other: 0}
    deadline = time.monotonic() + hang_guard(TIMEOUT)
    while counts[kind] < n:
        assert time.monotonic() < deadline, f"{n} {kind} messages did not come within {TIMEOUT} s"
        msg = client.recv_match(type=[kind, other], blocking=True, timeout=0.1)
        if msg is not None:
            counts[msg.get_type()] += 1
    return counts[kind] / max(counts[other], 1)


def arrive_before(client, kind: str, other: str, n: int) -> bool:
    """Whether a ``kind`` message comes before ``n`` messages of ``other`` (a stream that keeps coming)."""
    seen, deadline = 0, time.monotonic() + hang_guard(TIMEOUT)
    while seen < n:
        assert time.monotonic() < deadline, f"{n} {other} messages did not come within {TIMEOUT} s"
        msg = client.recv_match(type=[kind, other], blocking=True, timeout=0.1)
        if msg is not None:
            if msg.get_type() == kind:
                return True
            seen += 1
    return False


def upload_mission(client) -> tuple:
    """Take off to 5 m, fly ~10 m north, land; returns the HOME_POSITION message."""
    home = wait_for(client, "HOME_POSITION")
    frame = mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    items = [
        (mavlink.MAV_CMD_NAV_TAKEOFF, home.latitude, home.longitude, 5.0),
        (mavlink.MAV_CMD_NAV_WAYPOINT, home.latitude + 900, home.longitude, 5.0),  # 9e-5 degree: ~10 m north
        (mavlink.MAV_CMD_NAV_LAND, 0, 0, 0.0),
    ]
    client.mav.mission_count_send(1, 1, len(items), mavlink.MAV_MISSION_TYPE_MISSION)
    for _ in items:
        req = wait_for(client, "MISSION_REQUEST_INT")
        cmd, lat, lon, alt = items[req.seq]
        client.mav.mission_item_int_send(1, 1, req.seq, frame, cmd, 0, 1, 0, 0, 0, math.nan, lat, lon, alt, 0)
    ack = wait_for(client, "MISSION_ACK")
    assert ack.type == mavlink.MAV_MISSION_ACCEPTED
    return home


def test_mission_upload_and_download(link):
    client, vehicle = link
    home = upload_mission(client)
    assert len(vehicle.mission.items) == 3
    client.mav.mission_request_list_send(1, 1, mavlink.MAV_MISSION_TYPE_MISSION)
    assert wait_for(client, "MISSION_COUNT").count == 3
    client.mav.mission_request_int_send(1, 1, 1, mavlink.MAV_MISSION_TYPE_MISSION)
    item = wait_for(client, "MISSION_ITEM_INT")
    assert (item.seq, item.command, item.x) == (1, mavlink.MAV_CMD_NAV_WAYPOINT, home.latitude + 900)
    client.mav.mission_ack_send(1, 1, mavlink.MAV_MISSION_ACCEPTED, mavlink.MAV_MISSION_TYPE_MISSION)


def test_an_uploaded_mission_flies_in_auto_mission_mode(link):
    client, vehicle = link
    upload_mission(client)
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1) == mavlink.MAV_RESULT_ACCEPTED
    assert command(client, mavlink.MAV_CMD_MISSION_START, 0, 0) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "HEARTBEAT", lambda m: m.custom_mode == px4_custom_mode("MISSION"))
    wait_for(client, "MISSION_ITEM_REACHED", lambda m: m.seq == 1, timeout=10)
    x, y, z = vehicle.drone.telemetry().position  # the drone's own state now: the last sent may be from before
    assert abs(y - 10.0) < 2.5 and abs(x) < 0.5 and z == pytest.approx(5.0, abs=1.0)  # NAV_ACC_RAD is 2 m
    wait_for(client, "EXTENDED_SYS_STATE", lambda m: m.landed_state == mavlink.MAV_LANDED_STATE_ON_GROUND, timeout=10)
    assert vehicle.telemetry().position[1] == pytest.approx(10.0, abs=2.5)


def test_offboard_needs_streaming_setpoints_then_follows_them(link):
    client, _ = link
    offboard = (mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 6, 0)
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, *offboard) == mavlink.MAV_RESULT_DENIED  # no setpoints yet
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1) == mavlink.MAV_RESULT_ACCEPTED
    assert command(client, mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, math.nan, math.nan, math.nan) == (
        mavlink.MAV_RESULT_ACCEPTED
    )
    wait_for(client, "EXTENDED_SYS_STATE", lambda m: m.landed_state == mavlink.MAV_LANDED_STATE_IN_AIR, timeout=10)
    mask = 0b0000_1111_1111_1000  # position only

    def setpoint():  # 4 m north, 2 m up (NED), streamed as PX4 requires
        client.mav.set_position_target_local_ned_send(
            0, 1, 1, mavlink.MAV_FRAME_LOCAL_NED, mask, 4, 0, -2, 0, 0, 0, 0, 0, 0, 0, 0
        )

    setpoint()
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, *offboard) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "HEARTBEAT", lambda m: m.custom_mode == px4_custom_mode("OFFBOARD"))
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        setpoint()
        local = client.recv_match(type="LOCAL_POSITION_NED", blocking=True, timeout=0.1)
        if local is not None and abs(local.x - 4) < 0.3 and abs(local.z + 2) < 0.3:
            break
    else:
        pytest.fail("the vehicle did not reach the offboard setpoint")
    # Setpoints stop: after COM_OF_LOSS_T (wall time) the vehicle leaves OFFBOARD.
    wait_for(client, "HEARTBEAT", lambda m: m.custom_mode != px4_custom_mode("OFFBOARD"), timeout=4)


def test_a_bad_url_is_refused_with_a_clear_message():
    with pytest.raises(MavlinkVehicleError, match="bad MAVLink URL"):
        normalize_url("udp-out:nowhere")
    assert normalize_url("udpout://127.0.0.1:14540") == "udpout:127.0.0.1:14540"


@pytest.fixture
def copter():
    """A pymavlink client and the vehicle as ArduCopter (pre-arm checks pass at 2 s, GPS origin at 4 s; 4x)."""
    client = mavutil.mavlink_connection("udpin:127.0.0.1:0", source_system=255, source_component=190)
    port = client.port.getsockname()[1]
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=4.0,
                             autopilot="ardupilot", ekf=(2.0, 4.0))
    vehicle.start()
    try:
        wait_for(client, "HEARTBEAT")  # the client now knows where the vehicle is
        yield client, vehicle
    finally:
        vehicle.stop()
        client.close()


def received(client, seconds: float) -> set[str]:
    kinds, end = set(), time.monotonic() + seconds
    while time.monotonic() < end:
        msg = client.recv_match(blocking=True, timeout=0.05)
        if msg is not None:
            kinds.add(msg.get_type())
    return kinds


def test_as_ardupilot_only_heartbeats_come_until_a_stream_is_requested(copter):
    client, _ = copter
    home = wait_for(client, "HOME_POSITION")  # sent once, unasked, when the EKF gets its origin
    hb = wait_for(client, "HEARTBEAT")
    assert hb.type == mavlink.MAV_TYPE_QUADROTOR and hb.autopilot == mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA
    assert hb.custom_mode == 0  # STABILIZE
    assert not received(client, 1.0) - {"HEARTBEAT", "STATUSTEXT"}
    client.mav.request_data_stream_send(1, 1, mavlink.MAV_DATA_STREAM_EXTENDED_STATUS, 4, 1)
    status = wait_for(client, "SYS_STATUS")
    assert status.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_PREARM_CHECK
    assert "GLOBAL_POSITION_INT" not in received(client, 0.5)
    client.mav.request_data_stream_send(1, 1, mavlink.MAV_DATA_STREAM_POSITION, 5, 1)
    pos = wait_for(client, "GLOBAL_POSITION_INT")
    assert (pos.lat, pos.lon) == (home.latitude, home.longitude)
    assert command(client, mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, mavlink.MAVLINK_MSG_ID_EXTENDED_SYS_STATE,
                   200_000) == mavlink.MAV_RESULT_ACCEPTED
    wait_for(client, "EXTENDED_SYS_STATE")
    client.mav.request_data_stream_send(1, 1, mavlink.MAV_DATA_STREAM_ALL, 0, 0)  # stop them all
    time.sleep(0.3)
    assert "SYS_STATUS" not in received(client, 1.0)


def test_as_ardupilot_the_ekf_comes_up_armable_first_then_with_gps(copter):
    client, _ = copter
    client.mav.request_data_stream_send(1, 1, mavlink.MAV_DATA_STREAM_EXTENDED_STATUS, 10, 1)
    texts: list[str] = []
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1, texts=texts) == mavlink.MAV_RESULT_FAILED
    assert any(t.startswith("PreArm:") for t in texts), texts
    armable = wait_for(client, "SYS_STATUS",
                       lambda m: m.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_PREARM_CHECK)
    assert not armable.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_SENSOR_GPS  # no position yet
    wait_for(client, "SYS_STATUS", lambda m: m.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_SENSOR_GPS)
    wait_for(client, "GPS_RAW_INT", lambda m: m.fix_type >= mavlink.GPS_FIX_TYPE_3D_FIX)
    assert command(client, mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, ardupilotmega.MAVLINK_MSG_ID_EKF_STATUS_REPORT,
                   200_000) == mavlink.MAV_RESULT_ACCEPTED  # ArduPilot's own message, as MAVSDK 4 asks for it
    ekf = wait_for(client, "EKF_STATUS_REPORT")
    assert ekf.flags & ardupilotmega.EKF_POS_HORIZ_ABS and not ekf.flags & ardupilotmega.EKF_CONST_POS_MODE


def test_as_ardupilot_takeoff_needs_guided_and_goes_to_the_altitude_above_home(copter):
    client, _ = copter
    client.mav.request_data_stream_send(1, 1, mavlink.MAV_DATA_STREAM_ALL, 5, 1)
    wait_for(client, "HOME_POSITION")
    assert command(client, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1) == mavlink.MAV_RESULT_ACCEPTED
    texts: list[str] = []
    assert command(client, mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 4.0, texts=texts) == \
        mavlink.MAV_RESULT_FAILED  # in STABILIZE
    assert any("GUIDED" in t for t in texts), texts
    flags = mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | mavlink.MAV_MODE_FLAG_SAFETY_ARMED
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, flags, 4) == mavlink.MAV_RESULT_ACCEPTED  # GUIDED
    wait_for(client, "HEARTBEAT", lambda m: m.custom_mode == 4 and m.base_mode & mavlink.MAV_MODE_FLAG_GUIDED_ENABLED)
    assert command(client, mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 4.0) == mavlink.MAV_RESULT_ACCEPTED
    pos = wait_for(client, "GLOBAL_POSITION_INT", lambda m: m.relative_alt > 3800, timeout=10)
    assert pos.relative_alt < 4300
    assert command(client, mavlink.MAV_CMD_DO_SET_MODE, flags, 9) == mavlink.MAV_RESULT_ACCEPTED  # LAND
    wait_for(client, "HEARTBEAT", lambda m: m.custom_mode == 9)
    wait_for(client, "HEARTBEAT", lambda m: not m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED, timeout=15)
