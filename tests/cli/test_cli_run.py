"""``aeroexec run``: the example missions fly to completion on the simulator, and through MAVSDK against
``aeroexec sim``; a wrong mission never flies."""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from free_ports import free_udp_port

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"
RUNS = tempfile.TemporaryDirectory(prefix="aeroexec-runs-")  # where runs write their output folders


def aeroexec(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=timeout, cwd=RUNS.name)


def events(stdout: str, kind: str) -> list[str]:
    return [line for line in stdout.splitlines()
            if f"] {kind} " in line or f"] {kind}:" in line or line.endswith(f"] {kind}")]


def test_figure_10_flies_to_completion_on_the_simulator(tmp_path):
    log = tmp_path / "events.jsonl"
    result = aeroexec("run", str(MISSIONS / "figure10.py"), "--log", str(log))
    assert result.returncode == 0, result.stderr + result.stdout
    assert "figure10.py: completed" in result.stderr
    achieved = [line.split("GOAL_ACHIEVED ")[1].split(":")[0] for line in events(result.stdout, "GOAL_ACHIEVED")]
    assert achieved == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
    assert events(result.stdout, "activated") and "PAY_ATTENTION_TO_VISUAL_MARKERS" in result.stdout
    assert any("KEEP_HOVERING" in line for line in events(result.stdout, "reactive"))  # between the goals
    records = [json.loads(line) for line in log.read_text().splitlines()]
    events_only = [r for r in records if r["kind"] not in ("state", "log_closed")]
    assert events_only[-1]["kind"] == "engine_stopped" and any(r["kind"] == "mission_completed" for r in records)


def test_square_patrol_flies_to_completion_and_sees_markers():
    result = aeroexec("run", str(MISSIONS / "square_patrol.py"))
    assert result.returncode == 0, result.stderr + result.stdout
    assert len(events(result.stdout, "GOAL_ACHIEVED")) == 1 + 2 * 4 + 1 + 1
    assert "first marker seen:" in result.stdout


def test_a_wrong_mission_never_flies(tmp_path):
    mission = tmp_path / "wrong.py"
    mission.write_text(
        "import aeroexec.engine.api as api\n"
        "\n"
        "def mission():\n"
        "    api.execute_behavior('TAKE_OF')\n"
        "    api.execute_behavior('GO_TO_POINT', coordinates=[1, 2])\n"
        "    api.consult_belief('charge(battery, ?X')\n")
    result = aeroexec("run", str(mission))
    assert result.returncode == 1
    assert f"{mission}:4" in result.stderr and "The behavior TAKE_OF does not exist (did you mean TAKE_OFF?)" in \
        result.stderr
    assert f"{mission}:5" in result.stderr and "The value (1, 2) of argument COORDINATES" in result.stderr
    assert f"{mission}:6" in result.stderr and "The format of the belief expression" in result.stderr
    assert "the mission will not fly" in result.stderr and "activated" not in result.stdout
    assert "Traceback" not in result.stderr


def test_bad_options_are_one_clear_line(tmp_path):
    result = aeroexec("run", str(MISSIONS / "figure10.py"), "--drone", "gazebo")
    assert result.returncode == 1 and "expected sim or mavsdk:URL" in result.stderr
    result = aeroexec("run", str(tmp_path / "missing.py"))
    assert result.returncode == 1 and "cannot read the mission" in result.stderr
    assert "Traceback" not in result.stderr


def test_the_simulator_s_bad_vehicle_profile_is_one_line_naming_its_file_and_line(tmp_path):
    profile = tmp_path / "hexacopter.yaml"
    profile.write_text("name: hexa\nendurance: long\n")
    result = aeroexec("sim", "--vehicle", str(profile))
    assert result.returncode == 2 and result.stderr.strip() == (
        f"aeroexec sim: --vehicle {profile}:2: endurance (minutes of hover on a full battery) must be a number, "
        f"not 'long'"), result.stderr



@pytest.mark.mavsdk
@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_figure_10_flies_through_mavsdk_against_aeroexec_sim(autopilot):
    """As PX4 (streams unasked) and as ArduCopter (streams only what the adapter asks for, GUIDED takeoff)."""
    port = free_udp_port()
    sim = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "sim", "--speed", "4",
                            "--autopilot", autopilot, "--connect", f"udpout://127.0.0.1:{port}"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, cwd=RUNS.name)
    try:
        result = aeroexec("run", str(MISSIONS / "figure10.py"), "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                          timeout=150)
    finally:
        sim.terminate()
        try:
            sim.wait(timeout=10)
        except subprocess.TimeoutExpired:
            sim.kill()
    assert result.returncode == 0, result.stderr + result.stdout
    assert f"{autopilot} vehicle ready" in result.stderr
    achieved = [line.split("GOAL_ACHIEVED ")[1].split(":")[0] for line in events(result.stdout, "GOAL_ACHIEVED")]
    assert achieved == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
    assert events(result.stdout, "drone_disarmed")  # the run ends once the vehicle says it is disarmed
    assert result.stderr.strip().splitlines()[-1].startswith("figure10.py: completed")


def test_a_vehicle_that_never_gets_ready_is_one_clear_line_naming_what_is_missing():
    port = free_udp_port()  # nothing sends there
    result = aeroexec("run", str(MISSIONS / "figure10.py"), "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                      "--ready-timeout", "2")
    assert result.returncode == 1
    assert "the vehicle is not ready to fly after 2 s: no vehicle connected (--ready-timeout gives it longer)" in \
        result.stderr
    assert "Traceback" not in result.stderr and "activated" not in result.stdout


def test_marker_search_finds_marker_3_and_lands_on_it():
    result = aeroexec("run", str(MISSIONS / "marker_search.py"))
    assert result.returncode == 0, result.stderr + result.stdout
    landed = events(result.stdout, "drone_landed")[-1]
    x, y = (float(v) for v in landed.split("at (")[1].rstrip(")").split(","))
    assert abs(x - -13) < 0.5 and abs(y - -15) < 0.5  # marker 3's pad


@pytest.mark.parametrize("mission", ["go_to_point_y.py", "explore_region.py"])
def test_the_complex_behaviors_of_appendix_a_fly_to_completion(mission):
    result = aeroexec("run", str(MISSIONS / mission))
    assert result.returncode == 0, result.stderr + result.stdout
    assert not events(result.stdout, "WRONG_PROGRESS") and not events(result.stdout, "failed_preconditions")


def test_inspection_takes_a_photo_at_each_station(tmp_path):
    result = aeroexec("run", str(MISSIONS / "inspection.py"), "--output", str(tmp_path))
    assert result.returncode == 0, result.stderr + result.stdout
    photos = sorted(tmp_path.glob("photo_*.png"))
    assert len(photos) == 4 and all(p.read_bytes().startswith(b"\x89PNG") for p in photos)
