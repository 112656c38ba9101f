"""Drones in separate processes joined through the fleet's Zenoh router (mutual TLS, its access rules) on a free
loopback port, with the credentials the router made in its output folder."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.fleet.transport import free_endpoint
from processes import MISSIONS, aeroexec, stop, wait_for_line


@pytest.fixture
def router(tmp_path):
    """Start the router of a fleet of members flown elsewhere: ``router(fleet, *drones)`` -> (endpoint, the folder of
    the credentials it made)."""
    started = []

    def start(fleet: str, *drones: str) -> tuple[str, Path]:
        file = tmp_path / f"{fleet}.yaml"
        file.write_text(f"fleet: {fleet}\ndrones:\n" + "".join(f"  - {{name: {d}}}\n" for d in drones))
        endpoint = free_endpoint("tls")
        process = aeroexec("fleet", str(file), "--router", "--listen", endpoint, "--output", str(tmp_path / "router"),
                           cwd=tmp_path)
        started.append(process)
        wait_for_line(process, "listening on", 30)
        return endpoint, tmp_path / "router" / "credentials"

    yield start
    for process in started:
        process.send_signal(signal.SIGTERM)
        process.wait(10)


def test_a_broadcast_from_one_process_reaches_the_mission_waiting_for_it_in_another(router, tmp_path):
    endpoint, credentials = router("relay", "carrier", "scout")
    common = ("--fleet", "relay", "--connect", endpoint, "--credentials", str(credentials), "--speed", "4", "--plain")
    carrier = aeroexec("run", str(MISSIONS / "relay_carrier.py"), "--name", "carrier", "--output",
                       str(tmp_path / "carrier"), *common, cwd=tmp_path)
    try:
        wait_for_line(carrier, "joined fleet relay", 30)
        scout = aeroexec("run", str(MISSIONS / "relay_scout.py"), "--name", "scout", "--output",
                         str(tmp_path / "scout"), *common, cwd=tmp_path)
        scout_out, _ = scout.communicate(timeout=120)
        carrier_out, _ = carrier.communicate(timeout=120)
    finally:
        stop(carrier)
    assert scout.returncode == 0, scout_out[-3000:]
    assert carrier.returncode == 0, carrier_out[-3000:]
    assert "message_sent BROADCAST_MESSAGE: to carrier: area clear" in scout_out
    received = carrier_out.index("message_received: from scout: area clear")
    assert carrier_out.index("activated TAKE_OFF") > received


def test_a_drone_killed_mid_flight_is_reported_silent_and_the_other_finishes(router, tmp_path):
    endpoint, credentials = router("patrol", "victim", "survivor")
    common = ("--fleet", "patrol", "--connect", endpoint, "--credentials", str(credentials), "--plain")
    victim = aeroexec("run", str(MISSIONS / "square_patrol.py"), "--name", "victim", "--speed", "1",
                      "--output", str(tmp_path / "victim"), *common, cwd=tmp_path)
    survivor = None
    try:
        wait_for_line(victim, "joined fleet patrol", 30)
        survivor = aeroexec("run", str(MISSIONS / "square_patrol.py"), "--name", "survivor", "--speed", "3",
                            "--output", str(tmp_path / "survivor"), *common, cwd=tmp_path)
        before = wait_for_line(survivor, "fleet_drone_heard: victim is in the fleet", 30)
        wait_for_line(victim, "drone_takeoff_complete", 30)
        victim.kill()  # mid-flight, no goodbye
        victim.wait(10)
        out, _ = survivor.communicate(timeout=180)
    finally:
        stop(victim, *(p for p in (survivor,) if p is not None))
    out = "".join(before) + out
    assert survivor.returncode == 0, out[-3000:]
    assert "fleet_drone_silent: victim: nothing heard for" in out
    assert "mission_completed" in out
    assert out.index("fleet_drone_silent") < out.index("mission_completed")


def test_the_operator_commands_a_running_fleet_over_zenoh_with_its_identity_and_token(tmp_path):
    fleet = tmp_path / "wait.yaml"
    fleet.write_text(f"fleet: waiting\ndrones:\n  - {{name: w1, mission: {MISSIONS / 'relay_carrier.py'}}}\n"
                     f"  - {{name: w2, mission: {MISSIONS / 'relay_carrier.py'}, home: [3, 0]}}\n")
    out = tmp_path / "out"
    process = aeroexec("fleet", str(fleet), "--plain", "--speed", "1", "--output", str(out), cwd=tmp_path)
    try:
        wait_for_line(process, "fleet_drone_heard", 30)

        def ctl(*args: str, token: str | None = None) -> subprocess.CompletedProcess:
            env = {k: v for k, v in os.environ.items() if k != "AEROEXEC_FLEET_TOKEN"}
            extra = ("--token", token) if token else ()
            return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "ctl", "--fleet", "waiting", "--run",
                                   str(out), *extra, *args], capture_output=True, text=True, timeout=60, env=env)

        status = ctl("status")
        assert status.returncode == 0, status.stderr
        assert "w1: " in status.stdout and "w2: " in status.stdout and "battery" in status.stdout
        refused = ctl("abort", token="not-the-token")
        assert refused.returncode == 1 and "wrong token" in refused.stderr
        as_drone = ctl("abort", "--credentials", str(out / "credentials" / "w1.pem"))  # the token, not the identity
        assert as_drone.returncode == 1 and "no drone of fleet waiting answered" in as_drone.stderr, as_drone.stderr
        assert process.poll() is None  # nobody aborted
        aborted = ctl("abort", "--drone", "w2")
        assert aborted.returncode == 0 and "w2: " in aborted.stdout and "w1" not in aborted.stdout
        ctl("abort", "--drone", "w1")
        rest, _ = process.communicate(timeout=60)
    finally:
        stop(process)
    assert process.returncode == 1  # aborted missions did not complete
    assert "w2 | " in rest and "operator_command" in rest
