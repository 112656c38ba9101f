"""Faults end as faults: a MAVSDK run whose vehicle goes silent mid-flight exits non-zero and its last line says
why; a link that comes back within ``--link-grace`` lets the run land and disarm first."""

from __future__ import annotations

import queue
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from aeroexec.drones.interface import LandedState
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from free_ports import free_udp_port
from patience import hang_guard

pytestmark = pytest.mark.mavsdk

ROOT = Path(__file__).parents[2]
FIGURE10 = str(ROOT / "missions" / "figure10.py")
RUN_S = 120.0  # s, wall: longest any run below may take



class Run:
    """``aeroexec run`` in a subprocess, its stdout read line by line as it comes."""

    def __init__(self, tmp_path: Path, *args: str) -> None:
        self.process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", *args,
                                         "--output", str(tmp_path)],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        self.errors: list[str] = []  # stderr, drained as it comes so that the pipe never fills
        self._readers = [threading.Thread(target=self._read, daemon=True),
                         threading.Thread(target=lambda: self.errors.extend(self.process.stderr), daemon=True)]
        for reader in self._readers:
            reader.start()

    def _read(self) -> None:
        for line in self.process.stdout:
            self.lines.put(line.rstrip("\n"))

    def wait_for(self, text: str, timeout: float = 60.0) -> str:
        deadline = time.monotonic() + hang_guard(timeout)
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.1)
            except queue.Empty:
                if self.process.poll() is not None and self.lines.empty():
                    break
                continue
            self.seen.append(line)
            if text in line:
                return line
        pytest.fail(f"no line with {text!r} in the run's output:\n" + "\n".join(self.seen[-30:]))

    def finish(self) -> tuple[int, str, str]:
        try:
            self.process.wait(timeout=RUN_S)
        except subprocess.TimeoutExpired:
            self.process.kill()
            pytest.fail("the run did not end")
        for reader in self._readers:  # the pipes close with the process
            reader.join(timeout=10)
        while not self.lines.empty():
            self.seen.append(self.lines.get())
        return self.process.returncode, "\n".join(self.seen), "".join(self.errors)


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_killing_the_vehicle_mid_flight_fails_the_run_with_the_reason(tmp_path, autopilot):
    port = free_udp_port()
    sim = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "sim", "--speed", "4", "--autopilot", autopilot,
                            "--connect", f"udpout://127.0.0.1:{port}"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path)
    try:
        run = Run(tmp_path, FIGURE10, "--drone", f"mavsdk:udpin://127.0.0.1:{port}", "--link-grace", "2")
        run.wait_for("GOAL_ACHIEVED TAKE_OFF")
        sim.kill()  # the autopilot dies in the air
        code, out, err = run.finish()
    finally:
        sim.kill()
        sim.wait(timeout=10)
    assert code == 1, err
    last = err.strip().splitlines()[-1]
    assert last.startswith("failed: link lost at t="), err
    assert "with the drone in the air at" in last and "did not answer again" in last
    assert "figure10.py: failed" in err and "completed" not in err
    assert "waiting_for_link" in out and "link_not_back" in out


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_a_link_back_within_the_grace_time_lets_the_run_land_and_disarm(tmp_path, autopilot):
    port = free_udp_port()
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=4.0, autopilot=autopilot)
    vehicle.start()
    try:
        run = Run(tmp_path, FIGURE10, "--drone", f"mavsdk:udpin://127.0.0.1:{port}", "--link-grace", "30")
        run.wait_for("GOAL_ACHIEVED TAKE_OFF")
        vehicle.cut_link()  # the radio drops with the drone in the air
        run.wait_for("waiting_for_link")  # the mission's requests failed; the engine waits for the drone
        assert vehicle.telemetry().landed_state == LandedState.IN_AIR
        vehicle.restore_link()
        run.wait_for("link_back")
        code, out, err = run.finish()
        ground = vehicle.telemetry()
    finally:
        vehicle.stop()
    assert "GOAL_ACHIEVED LAND" in out.split("link_back")[1], out
    assert ground.landed_state == LandedState.ON_GROUND and not ground.armed
    assert code == 1, err  # the mission did not do what it was asked: its requests failed while the link was down
    last = err.strip().splitlines()[-1]
    assert last.startswith("failed: link lost at t=") and "with the drone in the air at" in last
    assert "(back at t=" in last and "left" not in last, err
