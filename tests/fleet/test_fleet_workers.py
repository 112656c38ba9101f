"""`aeroexec fleet --workers N`: the drones spread over worker processes, in lockstep through the fleet's router."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from aeroexec.cli.main import main
from patience import hang_guard

# each drone waits until the drone it follows is in the air (its position, shared over the fleet link), then takes
# off, says so and lands: a cascade over the whole fleet, across the workers
FOLLOWER = '''import aeroexec.engine.api as api


def mission():
    leader = {leader!r}
    waited = 0.0
    while leader and not api.true_belief(f"position({{leader}}, (?X, ?Y, ?Z)), ?Z > 1.5"):
        api.wait(0.2)
        waited += 0.2
        if waited > 120:
            raise RuntimeError(f"{{leader}} never took off")
    api.execute_behavior("TAKE_OFF", altitude=2)
    api.execute_behavior("BROADCAST_MESSAGE", message="up")
    api.execute_behavior("LAND")
'''


def cascade(folder: Path, n: int, seconds: float | None = None) -> Path:
    """A fleet of ``n`` drones d1..dn where each follows the drone of half its number (a tree of take-offs)."""
    side = math.ceil(math.sqrt(n))
    half = 2.0 * side + 8.0
    (folder / "field.yaml").write_text(f"home: {{lat: 40.4168, lon: -3.7038, alt: 650}}\n"
                                       f"bounds: {{min: [{-half}, {-half}, 0], max: [{half}, {half}, 20]}}\n")
    lines = ["fleet: cascade", "world: field.yaml", "drones:"]
    for i in range(1, n + 1):
        leader = f"d{i // 2}" if i > 1 else ""
        mission = folder / f"m{i}.py"
        text = FOLLOWER.format(leader=leader)
        if seconds is not None:  # fly on until stopped
            text = text.replace('    api.execute_behavior("LAND")\n', f'    api.wait({seconds})\n'
                                                                       f'    api.execute_behavior("LAND")\n')
        mission.write_text(text)
        x, y = -2.0 * (side - 1) + 4 * ((i - 1) % side), -2.0 * (side - 1) + 4 * ((i - 1) // side)
        lines.append(f"  - {{name: d{i}, mission: m{i}.py, home: [{x:g}, {y:g}], seed: {i}}}")
    path = folder / "fleet.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def events(folder: Path, drone: str) -> list[dict]:
    return [json.loads(line) for line in (folder / drone / "events.jsonl").read_text().splitlines()]


def test_a_fleet_of_50_over_2_workers_writes_the_same_event_logs_as_in_one_process(tmp_path):
    fleet = cascade(tmp_path, 50)
    for workers in (1, 2):  # in processes of their own, with a time limit: a lockstep that waits forever fails
        flown = subprocess.run([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--workers", str(workers),
                                "--quiet", "--output", str(tmp_path / f"w{workers}")], capture_output=True, text=True,
                               timeout=300)
        assert flown.returncode == 0, flown.stderr
    status = json.loads((tmp_path / "w2" / "fleet_status.json").read_text())
    assert status["status"] == "completed" and status["time"]["workers"] == 2
    for i in range(1, 51):
        one, two = events(tmp_path / "w1", f"d{i}"), events(tmp_path / "w2", f"d{i}")
        assert one[1:] == two[1:], f"d{i}"  # the first line names the output folder
        if i > 1:  # the cascade went through the fleet link: d{i} took off after its leader was in the air
            leader = events(tmp_path / "w1", f"d{i // 2}")
            up = next(e["time"] for e in leader if e["kind"] == "GOAL_ACHIEVED" and e["behavior"] == "TAKE_OFF")
            takes_off = next(e["time"] for e in one if e["kind"] == "activated" and e["behavior"] == "TAKE_OFF")
            assert takes_off > up - 2.0, f"d{i}"
    heard = [e for e in events(tmp_path / "w2", "d50") if e["kind"] == "message_received"]
    assert {e["data"]["sender"] for e in heard} >= {"d1", "d49"}  # from both workers


def test_options_that_need_one_process_are_refused_with_workers(tmp_path, capsys):
    fleet = cascade(tmp_path, 2)
    assert main(["fleet", str(fleet), "--workers", "2", "--web", "--output", str(tmp_path / "a")]) == 2
    assert "--web needs every drone in this process: use --workers 1" in capsys.readouterr().err
    assert main(["fleet", str(fleet), "--workers", "0", "--output", str(tmp_path / "b")]) == 2
    assert "--workers 0: at least 1" in capsys.readouterr().err
    worker = subprocess.run([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--worker"], input="hello\n",
                            capture_output=True, text=True, timeout=60)
    assert worker.returncode == 2 and "only aeroexec fleet starts workers" in worker.stderr


def _workers(coordinator: subprocess.Popen) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(coordinator.pid)], capture_output=True, text=True).stdout
    return [int(pid) for pid in out.split()]


def _fly(tmp_path: Path, n: int) -> subprocess.Popen:
    fleet = cascade(tmp_path, n, seconds=600)
    return subprocess.Popen([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--workers", "2", "--speed",
                             "4", "--plain", "--output", str(tmp_path / "out")], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})


def _wait_until_all_up(tmp_path: Path, n: int, process: subprocess.Popen, timeout: float = 90.0) -> None:
    deadline = time.monotonic() + hang_guard(timeout)
    while time.monotonic() < deadline:
        logs = [tmp_path / "out" / f"d{i}" / "events.jsonl" for i in range(1, n + 1)]
        if all(p.exists() and '"BROADCAST_MESSAGE"' in p.read_text() for p in logs):
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.2)
    process.kill()
    pytest.fail("the fleet's drones were not all in the air in time")


def test_ctrl_c_to_the_fleet_lands_every_drone_of_every_worker(tmp_path):
    process = _fly(tmp_path, 4)
    try:
        _wait_until_all_up(tmp_path, 4, process)
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=90)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 1, err
    for i in range(1, 5):
        log = events(tmp_path / "out", f"d{i}")
        assert any(e["kind"] == "operator_interrupt" for e in log), f"d{i}"
        assert f"d{i}: m{i}.py aborted" in err and "landed" in err.split(f"d{i}: m{i}.py")[1].splitlines()[0]
    assert json.loads((tmp_path / "out" / "fleet_status.json").read_text())["status"] == "aborted"


def test_a_worker_that_dies_fails_its_drones_and_the_others_land(tmp_path):
    process = _fly(tmp_path, 4)
    try:
        _wait_until_all_up(tmp_path, 4, process)
        workers = _workers(process)
        assert len(workers) == 2, workers
        os.kill(max(workers), signal.SIGKILL)  # the second worker, flying d3 and d4
        time.sleep(1.0)
        process.send_signal(signal.SIGTERM)  # the rest of the fleet is told to land
        out, err = process.communicate(timeout=90)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 1
    assert "the worker flying d3, d4 ended unexpectedly (exit status -9): its drones are reported failed" in err
    status = json.loads((tmp_path / "out" / "fleet_status.json").read_text())
    assert status["drones"]["d3"]["status"] == "failed" and status["drones"]["d4"]["status"] == "failed"
    for drone in ("d1", "d2"):  # the other worker went on without it and landed its drones
        assert status["drones"][drone]["status"] == "aborted"
        assert f"{drone}: " in err and "landed" in err.split(f"{drone}: m")[1].splitlines()[0]


def test_a_worker_lost_mid_flight_is_reported_and_the_other_workers_drones_fly_their_missions_to_the_end(tmp_path):
    """kill -9 of one worker and nothing else: its drones are reported failed with the reason, the other worker's
    fly on to the end of their missions and land (completed), and the fleet's exit status (1) and status file say
    that not every drone completed."""
    fleet = cascade(tmp_path, 4, seconds=60)  # after the cascade, 60 s of flight left (15 s at --speed 4)
    process = subprocess.Popen([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--workers", "2", "--speed",
                                "4", "--plain", "--output", str(tmp_path / "out")], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        _wait_until_all_up(tmp_path, 4, process)
        workers = _workers(process)
        assert len(workers) == 2, workers
        os.kill(max(workers), signal.SIGKILL)  # the second worker, flying d3 and d4
        out, err = process.communicate(timeout=hang_guard(120))
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 1, err
    assert "the worker flying d3, d4 ended unexpectedly (exit status -9): its drones are reported failed; the others " \
           "fly on" in err, err
    status = json.loads((tmp_path / "out" / "fleet_status.json").read_text())
    assert status["exit_status"] == 1 and status["status"] == "mixed", status
    for drone in ("d3", "d4"):
        assert status["drones"][drone]["status"] == "failed", status["drones"][drone]
        assert "its worker process ended unexpectedly (exit status -9)" in status["drones"][drone]["reasons"][0]
    for drone in ("d1", "d2"):  # flew the rest of their missions: the wait, then LAND
        assert status["drones"][drone]["status"] == "completed", status["drones"][drone]
        log = events(tmp_path / "out", drone)
        assert [e["landed_state"] for e in log if e["kind"] == "state"][-1] == "on_ground", drone
        assert any(e["kind"] == "drone_disarmed" for e in log), drone


def test_a_mission_a_worker_cannot_fly_is_named_with_its_line_and_nothing_flies(tmp_path):
    fleet = cascade(tmp_path, 4)
    (tmp_path / "m4.py").write_text("import aeroexec.engine.api as api\n\n\ndef mission(:\n    pass\n")
    flown = subprocess.run([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--workers", "2", "--quiet",
                            "--output", str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert flown.returncode == 1, flown.stderr
    assert "m4.py:4" in flown.stderr and "the worker flying d3, d4 ended before its drones took off" in flown.stderr
    assert "internal error" not in flown.stderr and "Traceback" not in flown.stderr
    assert not any((tmp_path / "out" / d / "events.jsonl").exists() and "TAKE_OFF" in
                   (tmp_path / "out" / d / "events.jsonl").read_text() for d in ("d1", "d2", "d3", "d4"))


def test_the_operator_commands_the_drones_of_every_worker_with_ctl(tmp_path):
    waiting = Path(__file__).resolve().parents[2] / "missions" / "relay_carrier.py"  # waits on the ground
    fleet = tmp_path / "wait.yaml"
    fleet.write_text("fleet: waiting\ndrones:\n" + "".join(
        f"  - {{name: w{i}, mission: {waiting}, home: [{3 * i}, 0]}}\n" for i in range(1, 5)))
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--workers", "2", "--plain",
                                "--speed", "1", "--output", str(out)], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)

    def ctl(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "aeroexec", "ctl", "--fleet", "waiting", "--run", str(out),
                               *args], capture_output=True, text=True, timeout=60)

    try:
        deadline = time.monotonic() + 60
        while not (out / "w4" / "events.jsonl").exists() or "fleet_drone_heard" not in (
                out / "w4" / "events.jsonl").read_text():
            assert time.monotonic() < deadline and process.poll() is None, "the fleet never flew"
            time.sleep(0.2)
        status = ctl("status")
        assert status.returncode == 0, status.stderr
        assert all(f"w{i}: " in status.stdout for i in range(1, 5)), status.stdout  # both workers answered
        aborted = ctl("abort", "--drone", "w4")  # a drone of the second worker
        assert aborted.returncode == 0 and "w4: " in aborted.stdout and "w1" not in aborted.stdout
        assert ctl("abort").returncode == 0
        rest, _ = process.communicate(timeout=90)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 1  # aborted missions did not complete
    assert "w4 | " in rest and "operator_command" in rest


def test_workers_whose_coordinator_is_killed_land_their_drones_and_end(tmp_path):
    process = _fly(tmp_path, 4)
    try:
        _wait_until_all_up(tmp_path, 4, process)
        workers = _workers(process)
        process.kill()  # the coordinator and its router gone at once
        process.wait(10)
        deadline = time.monotonic() + 60
        while any(Path(f"/proc/{pid}").exists() and "zombie" not in Path(f"/proc/{pid}/status").read_text().lower()
                  for pid in workers):
            assert time.monotonic() < deadline, "a worker did not end"
            time.sleep(0.2)
    finally:
        if process.poll() is None:
            process.kill()
    for i in range(1, 5):
        log = events(tmp_path / "out", f"d{i}")
        assert log[-1]["kind"] == "log_closed", f"d{i}"
        ended = next(e for e in log if e["kind"] == "run_ended")
        assert ended["detail"] == "aborted" and any(
            e["kind"] == "operator_interrupt" and "coordinator ended" in e["detail"] for e in log), f"d{i}"
        assert [e["landed_state"] for e in log if e["kind"] == "state"][-1] == "on_ground", f"d{i}"
        assert any(e["kind"] == "drone_disarmed" for e in log), f"d{i}"
