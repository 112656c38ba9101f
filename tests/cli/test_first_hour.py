"""A newcomer's first hour (issue 35, points 2, 5 and 6): the mistakes a new user makes get one clear line, the
right exit status and the right stream; the words agree in number and with the robot."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
ROVER = ROOT / "examples" / "rover" / "missions"


def aeroexec(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=120, cwd=cwd)


@pytest.fixture(scope="module")
def flown(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("flown") / "out"
    result = aeroexec("run", "missions/figure10.xml", "--quiet", "--output", str(folder))
    assert result.returncode == 0, result.stderr
    return folder


def test_a_rover_mission_without_robot_names_the_robot_kind_to_give():
    checked = aeroexec("verify", str(ROVER / "patrol.xml"))
    assert checked.returncode == 1
    assert (f"{ROVER / 'patrol.xml'}: hint: DRIVE_TO_POINT, TURN, FOLLOW_WALL, DOCK are behaviors of the robot kind "
            f"rover: give --robot rover") in checked.stdout.splitlines()
    flown = aeroexec("run", str(ROVER / "patrol.py"), "--quiet")
    assert flown.returncode == 1 and flown.stdout == ""
    assert (f"{ROVER / 'patrol.py'}: hint: DRIVE_TO_POINT, TURN, DOCK are behaviors of the robot kind rover: give "
            f"--robot rover") in flown.stderr.splitlines()
    assert flown.stderr.rstrip().endswith("3 errors; the mission will not fly")


def test_a_drone_mission_given_to_the_rover_names_the_drone_and_the_rover_does_not_fly():
    checked = aeroexec("verify", "missions/figure10.xml", "--robot", "rover")
    assert checked.returncode == 1
    assert "give --robot drone (the default)" in checked.stdout
    assert checked.stdout.rstrip().endswith("; will not run")
    fine = aeroexec("verify", str(ROVER / "patrol.xml"), "--robot", "rover")
    assert fine.returncode == 0 and "; ready to run" in fine.stdout and "fly" not in fine.stdout
    refused = aeroexec("run", "missions/figure10.py", "--robot", "rover", "--quiet")
    assert refused.returncode == 1 and "the mission will not run" in refused.stderr


def test_a_misspelt_option_is_refused_by_its_command_with_the_option_meant():
    result = aeroexec("run", "missions/figure10.py", "--sped", "2")
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.startswith("usage: aeroexec run ")
    assert result.stderr.splitlines()[-1] == \
        "aeroexec run: error: unrecognized arguments: --sped 2 (did you mean --speed?)"
    nothing_close = aeroexec("verify", "missions/figure10.xml", "--zzz")
    assert nothing_close.returncode == 2
    assert nothing_close.stderr.splitlines()[-1] == "aeroexec verify: error: unrecognized arguments: --zzz"


def test_a_folder_given_as_the_mission_is_said_to_be_a_folder(tmp_path):
    (tmp_path / "mine.py").write_text("def mission():\n    pass\n")
    result = aeroexec("run", str(tmp_path))
    assert result.returncode == 1 and result.stdout == ""
    assert result.stderr.strip() == (f"{tmp_path}: it is a directory, not a mission file: give the mission's file "
                                     f"(missions in it: mine.py)")
    missing = aeroexec("verify", str(tmp_path / "nothere"))
    assert missing.returncode == 1 and "nothere: no such file: a mission is a Python program" in missing.stdout


def test_an_unclosed_tag_is_reported_with_the_line_where_it_was_opened(tmp_path):
    mission = tmp_path / "unclosed.xml"
    mission.write_text('<root BTCPP_format="4">\n  <BehaviorTree ID="Main">\n    <Sequence>\n      <TAKE_OFF>\n'
                       '      <LAND/>\n    </Sequence>\n  </BehaviorTree>\n</root>\n')
    result = aeroexec("verify", str(mission))
    assert result.returncode == 1
    assert result.stdout.splitlines()[0] == (
        f"{mission}:6: error: not well-formed XML: mismatched tag </Sequence>: <TAKE_OFF> opened at line 4 is still "
        f"open (close it: <TAKE_OFF .../> or </TAKE_OFF>)")
    cut = tmp_path / "cut.xml"
    cut.write_text('<root BTCPP_format="4">\n  <BehaviorTree ID="Main">\n    <Sequence>\n      <LAND/>\n')
    assert "the file ends while <Sequence> opened at line 3 is still open" in aeroexec("verify", str(cut)).stdout


def test_strict_btcpp_on_a_python_mission_says_there_is_no_tree_to_check():
    result = aeroexec("verify", "--strict-btcpp", "missions/figure10.py")
    assert result.returncode == 0
    assert ("missions/figure10.py: warning: --strict-btcpp checks behavior trees against BehaviorTree.CPP and "
            "Groot2; a Python mission has no tree to check") in result.stdout
    assert "0 errors, 1 warning; ready to fly" in result.stdout


def test_beliefs_report_and_console_take_a_run_folder_or_its_log_alike(flown, tmp_path):
    for run in (flown, flown / "events.jsonl"):
        answered = aeroexec("beliefs", str(run), "-q", "flight_state(self, ?S)")
        assert answered.returncode == 0 and "landed" in answered.stdout, answered.stderr
        assert answered.stderr.startswith(f"{flown / 'events.jsonl'}: ")
    report = aeroexec("report", str(flown), "--output", str(tmp_path / "report"))
    assert report.returncode == 0, report.stderr
    assert (tmp_path / "report" / "report.html").is_file()
    for command in ("beliefs", "report", "console"):
        wrong = aeroexec(command, str(tmp_path / "nothing"))
        assert wrong.returncode == 1 and wrong.stdout == ""
        assert wrong.stderr.strip() == (f"{tmp_path / 'nothing'}: no event log here (a run's output folder, its "
                                        f"events.jsonl or its journal.sqlite is expected)")


def test_beliefs_without_a_run_names_the_one_it_answers_from_before_answering(flown, tmp_path):
    nothing = aeroexec("beliefs", "-q", "flight_state(self, ?S)", cwd=tmp_path)
    assert nothing.returncode == 1 and nothing.stdout == ""
    assert "no run given and none in aeroexec_output/: name a run's output folder or its event log" in nothing.stderr
    newest = tmp_path / "aeroexec_output" / "20260101-120000"
    newest.mkdir(parents=True)
    (newest / "events.jsonl").write_bytes((flown / "events.jsonl").read_bytes())
    answered = aeroexec("beliefs", "-q", "flight_state(self, ?S)", cwd=tmp_path)
    assert answered.returncode == 0 and "landed" in answered.stdout
    first = answered.stderr.splitlines()[0]
    assert first.startswith("aeroexec_output/20260101-120000/events.jsonl (the newest run in aeroexec_output/; "
                            "name another: aeroexec beliefs RUN_DIR): ")


def test_the_report_counts_in_words_that_agree_and_says_what_it_draws(flown, tmp_path):
    result = aeroexec("report", str(flown / "events.jsonl"), "--output", str(tmp_path))
    assert result.returncode == 0
    steps = [line for line in result.stderr.splitlines() if line.startswith("report: ")]
    assert steps[0] == f"report: reading {flown / 'events.jsonl'} ..."
    assert [s for s in steps if s.startswith("report: drawing ")] == [
        "report: drawing path.png ...", "report: drawing flight.png ...", "report: drawing timeline.png ..."]
    assert result.stderr.splitlines()[-1].endswith(", 0 failures")
    assert re.search(r"\b1 failures\b", result.stderr) is None


@pytest.mark.mavsdk
def test_the_plain_mavsdk_demo_prints_mavsdks_log_plain_and_without_debug_lines():
    from aeroexec.drones.sim import SimulatedDrone
    from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
    from free_ports import free_udp_port

    port = free_udp_port()
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=8.0)
    vehicle.start()
    try:
        demo = subprocess.run([sys.executable, "-m", "aeroexec.drones.mavsdk.demo", "--url",
                               f"udpin://127.0.0.1:{port}", "--altitude", "2", "--side", "2", "--timeout", "30"],
                              capture_output=True, text=True, timeout=90)
    finally:
        vehicle.stop()
    assert demo.returncode == 0, demo.stderr
    assert "\x1b" not in demo.stdout + demo.stderr  # no colour codes in a pipe
    assert demo.stdout.splitlines()[-1] == "landed and disarmed"
    assert "mavsdk info: MAVSDK version" in demo.stderr
    assert "Armed" not in demo.stderr  # the vehicle's status texts are MAVSDK debug lines: only with --verbose
