"""The vehicle a user flies: a profile (``--vehicle FILE``: endurance, speeds, rates, ceiling) used by verify's
route, the simulator and the safety rules; and ArduPilot's patrol forever (DO_JUMP repeat -1), flown until the
mission is stopped."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.drones.profile import VehicleProfileError, parse_vehicle_profile

ROOT = Path(__file__).parents[2]
DATA = Path(__file__).with_name("data")
#: QGroundControl's own ArduCopter SITL plan (real_missions/SOURCES.md): 21.9 km, about 42 minutes at its speeds.
LONG_PLAN = DATA / "real_missions" / "qgroundcontrol" / "ArduPilotSITL-ArduCopter.plan"
#: ArduPilot's own SITL mission with DO_JUMP repeat -1 (patrols/SOURCES.md).
PATROL = DATA / "patrols" / "CMAC-bigloop.txt"
LONG_RANGE = "name: long-range hexacopter\nendurance: 75  # minutes of hover\ncruise_speed: 8\nceiling: 200\n"


def aeroexec(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=600, cwd=ROOT)


def records(folder: Path) -> list[dict]:
    return [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]


def test_a_long_plan_is_refused_for_the_default_battery_with_a_message_that_names_vehicle(tmp_path):
    verified = aeroexec("verify", str(LONG_PLAN))
    assert verified.returncode == 1
    assert "the battery runs down to its 7% failsafe here" in verified.stdout
    assert "20 min of hover" in verified.stdout and "--vehicle FILE" in verified.stdout
    run = aeroexec("run", str(LONG_PLAN), "--quiet", "--output", str(tmp_path / "run"))
    assert run.returncode == 1 and "--vehicle FILE" in run.stderr and "will not fly" in run.stderr


def test_the_long_plan_flies_to_completion_with_a_profile_that_allows_it(tmp_path):
    profile = tmp_path / "hexacopter.yaml"
    profile.write_text(LONG_RANGE)
    verified = aeroexec("verify", str(LONG_PLAN), "--vehicle", str(profile))
    assert verified.returncode == 0, verified.stdout
    assert "75 min of hover" in verified.stdout
    run = aeroexec("run", str(LONG_PLAN), "--vehicle", str(profile), "--max-time", "4000", "--quiet",
                   "--output", str(tmp_path / "run"))
    assert run.returncode == 0, run.stderr[-2000:]
    assert ": completed at t=" in run.stderr
    log = records(tmp_path / "run")
    last = [r for r in log if r["kind"] == "state"][-1]
    assert last["landed_state"] == "on_ground" and not last["armed"]
    assert 1800.0 < last["time"] < 4000.0  # it flew the whole plan, longer than the default battery's 20 minutes
    assert last["battery"] > 7.0  # the simulator flew the profile's battery: it landed above the failsafe


def test_without_a_longer_time_limit_the_run_warns_that_the_route_outlasts_it(tmp_path):
    profile = tmp_path / "hexacopter.yaml"
    profile.write_text(LONG_RANGE)
    run = aeroexec("run", str(LONG_PLAN), "--vehicle", str(profile), "--quiet", "--output", str(tmp_path / "run"))
    assert "longer than the run's time limit of 1800 s" in run.stderr and "give --max-time" in run.stderr
    assert run.returncode == 1  # the time limit cut it: never 'completed'


def test_the_profile_s_ceiling_refuses_a_route_that_climbs_above_it(tmp_path):
    profile = tmp_path / "low.yaml"
    profile.write_text("endurance: 75\nceiling: 120\n")
    verified = aeroexec("verify", str(LONG_PLAN), "--vehicle", str(profile))
    assert verified.returncode == 1
    assert "item 4: (3003.6, -0.5, 150) is 150 m above home, higher than the vehicle's ceiling of 120 m" in \
        verified.stdout


@pytest.mark.parametrize(("text", "line", "says"), [
    ("endurance: 75\ncruise_speed: fast\n", 2, "cruise_speed (m/s) must be a number, not 'fast'"),
    ("endurance: 75\nendurence: 3\n", 2, "unknown key 'endurence'"),
    ("endurance: -5\n", 1, "endurance (minutes of hover on a full battery) must be positive"),
    ("max_speed: 4\ncruise_speed: 6\n", 2, "cruise_speed 6 m/s is above max_speed 4 m/s"),
    ("- endurance\n", 1, "a vehicle profile is a mapping"),
])
def test_a_wrong_profile_is_refused_at_its_file_and_line(tmp_path, text, line, says):
    with pytest.raises(VehicleProfileError, match=rf"^v\.yaml:{line}: ") as error:
        parse_vehicle_profile(text, "v.yaml")
    assert says in str(error.value)
    profile = tmp_path / "v.yaml"
    profile.write_text(text)
    run = aeroexec("run", str(LONG_PLAN), "--vehicle", str(profile), "--quiet", "--output", str(tmp_path / "r"))
    assert run.returncode == 1 and f"--vehicle {profile}:{line}: " in run.stderr and "Traceback" not in run.stderr


def test_a_patrol_for_ever_verifies_with_a_warning_and_is_suspended_by_the_time_limit_landed(tmp_path):
    verified = aeroexec("verify", str(PATROL))
    assert verified.returncode == 0, verified.stdout
    assert f"{PATROL}:7: warning: WRONG_SEQUENCE: item 5: DO_JUMP repeats forever (repeat count -1) items 1-4: " \
           f"the drone patrols until the mission is stopped" in verified.stdout
    assert "a patrol repeated forever, its first round" in verified.stdout
    run = aeroexec("run", str(PATROL), "--max-time", "900", "--quiet", "--output", str(tmp_path / "run"))
    assert run.returncode == 5, run.stderr[-2000:]  # suspended: not completed, and not a failure of the mission
    assert ": suspended at t=" in run.stderr
    assert "the time limit (--max-time 900 s) stopped the patrol that repeats forever" in run.stderr
    log = records(tmp_path / "run")
    rounds = [r for r in log if r["kind"] == "node_status" and r["data"]["node"] == "item 4 WAYPOINT"
              and r["data"]["new"] == "SUCCESS"]
    assert len(rounds) >= 2  # it went round again and again
    assert sum(r["kind"] == "node_status" and r["data"]["node"] == "item 1 take-off"
               and r["data"]["new"] == "SUCCESS" for r in log) == 1  # the jump repeats the flight, not the take-off
    last = [r for r in log if r["kind"] == "state"][-1]
    assert last["landed_state"] == "on_ground" and not last["armed"]
    ended = next(r for r in log if r["kind"] == "run_ended")
    assert ended["detail"] == "suspended" and ended["data"]["exit_status"] == 5


def test_a_vehicle_without_a_camera_is_a_verify_warning_and_its_photos_a_logged_skip(tmp_path):
    sample = DATA / "real_missions" / "mavsdk" / "qgroundcontrol_sample.plan"  # QGroundControl's: a photo item
    profile = tmp_path / "no_camera.yaml"
    profile.write_text("name: mapping frame without its camera\ncamera: false\n")
    verified = aeroexec("verify", str(sample), "--vehicle", str(profile))
    assert verified.returncode == 0
    assert f"{sample}:55: warning: item 3: the vehicle has no camera: the mission's 1 photo behavior" in verified.stdout
    run = aeroexec("run", str(sample), "--vehicle", str(profile), "--quiet", "--output", str(tmp_path / "run"))
    assert run.returncode == 0 and ": completed at t=" in run.stderr
    log = records(tmp_path / "run")
    assert [r["behavior"] for r in log if r["kind"] == "photo_skipped"] == ["TAKE_PHOTO"]
    assert not [r for r in log if r["kind"] == "photo_taken"] and not list((tmp_path / "run").glob("photo_*.png"))
    with_camera = aeroexec("run", str(sample), "--quiet", "--output", str(tmp_path / "camera"))
    assert with_camera.returncode == 0 and list((tmp_path / "camera").glob("photo_*.png"))
