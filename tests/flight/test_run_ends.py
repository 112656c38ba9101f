"""Every way a run ends lands the drone and tells the truth: SIGTERM and SIGHUP like Ctrl-C (abort, land, a
complete log, exit 4), Ctrl-C before take-off (130, one line), an output folder that cannot be used (2, before
anything flies), a full disk (whole lines only, exit 6, said once), a closed stdout (quiet, exit 0)."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys

import pytest
from aeroexec.drones.interface import LandedState
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from flight_runs import MISSIONS, RUN_S, Command, ended, landed, read_log
from free_ports import free_udp_port

FIGURE10 = str(MISSIONS / "figure10.py")
FIGURE10_TREE = str(MISSIONS / "figure10.xml")


@pytest.mark.parametrize("number", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
@pytest.mark.parametrize("mission", [FIGURE10, FIGURE10_TREE], ids=["python", "tree"])
def test_a_signal_mid_flight_aborts_lands_and_closes_the_log(tmp_path, number, mission):
    run = Command(tmp_path, "run", mission, "--plain", "--speed", "4", "--output", str(tmp_path / "out"))
    run.wait_for("GOAL_ACHIEVED TAKE_OFF")
    run.signal(number)
    code, out, err = run.finish()
    name = signal.Signals(number).name
    assert code == 4, err
    assert f"interrupted by the operator ({name}): aborting and landing" in err
    assert "Traceback" not in err
    records = read_log(tmp_path / "out" / "events.jsonl")
    assert ended(records)["detail"] == "aborted" and records[-1]["kind"] == "log_closed"
    assert any(r["kind"] == "operator_interrupt" and r["detail"] == name for r in records)
    assert landed(records), "the drone was left in the air"
    assert "aborted at t=" in err.splitlines()[-2] or "aborted at t=" in err


@pytest.mark.mavsdk
@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_sigterm_mid_flight_lands_a_mavsdk_vehicle(tmp_path, autopilot):
    port = free_udp_port()
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=4.0, autopilot=autopilot)
    vehicle.start()
    try:
        run = Command(tmp_path, "run", FIGURE10, "--plain", "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                      "--output", str(tmp_path / "out"))
        run.wait_for("GOAL_ACHIEVED TAKE_OFF")
        assert vehicle.telemetry().landed_state == LandedState.IN_AIR
        run.signal(signal.SIGTERM)
        code, out, err = run.finish()
        ground = vehicle.telemetry()
    finally:
        vehicle.stop()
    assert code == 4, err
    assert ground.landed_state == LandedState.ON_GROUND and not ground.armed, "left in the air or armed"
    records = read_log(tmp_path / "out" / "events.jsonl")
    assert ended(records)["detail"] == "aborted" and records[-1]["kind"] == "log_closed"


@pytest.mark.mavsdk
def test_ctrl_c_before_take_off_exits_130_with_one_line(tmp_path):
    port = free_udp_port()  # no vehicle there: the run waits for one
    run = Command(tmp_path, "run", FIGURE10, "--plain", "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                  "--output", str(tmp_path / "out"))
    run.wait_for("waiting up to")
    run.signal(signal.SIGINT)
    code, out, err = run.finish(timeout=30)
    assert code == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.splitlines()[-1] == "interrupted before take-off (Ctrl-C): nothing flew"


@pytest.mark.parametrize("how", ["a file", "under a file"])
def test_an_output_folder_that_cannot_be_used_is_refused_before_take_off(tmp_path, how):
    blocker = tmp_path / "taken"
    blocker.write_text("not a folder\n")
    output = blocker if how == "a file" else blocker / "run"
    result = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", FIGURE10, "--plain", "--output",
                             str(output)], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert f"--output {output}:" in result.stderr and "folder" in result.stderr
    assert "activated" not in result.stdout and "internal error" not in result.stderr


# python -c FULL_DISK ROOM ARGS...: aeroexec ARGS on a disk that fills after ROOM bytes of the event log (the write
# that crosses it is cut short, every later one fails with ENOSPC); the campaign's own
from aeroexec.rehearsal.simulation.processes import FULL_DISK  # noqa: E402


def test_a_full_disk_leaves_whole_lines_a_flight_that_lands_and_says_so_once(tmp_path):
    result = subprocess.run([sys.executable, "-c", FULL_DISK, "6000", "run", FIGURE10, "--plain", "--output",
                             str(tmp_path / "out")], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert result.returncode == 6, result.stderr
    records = read_log(tmp_path / "out" / "events.jsonl")  # every line whole
    assert len(records) > 10 and all(r["kind"] != "log_closed" for r in records)  # no claim to be complete
    assert sum("cannot be written" in line for line in result.stderr.splitlines()) == 1, result.stderr
    assert "figure10.py: completed" in result.stderr
    assert "the event log is incomplete (No space left on device)" in result.stderr
    assert "GOAL_ACHIEVED LAND" in result.stdout  # the flight went on to its end


PHOTOS_ON_A_FULL_DISK = """
import errno, os, pathlib, sys

write_bytes = pathlib.Path.write_bytes


def full(path, data):  # the disk is full when the photos come: each write of one fails part way
    if path.name.startswith("photo_"):
        write_bytes(path, bytes(data[:100]))
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    return write_bytes(path, data)


pathlib.Path.write_bytes = full
from aeroexec.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


def test_photos_that_cannot_be_saved_are_said_once_and_the_survey_flies_on_and_lands_at_home(tmp_path):
    result = subprocess.run([sys.executable, "-c", PHOTOS_ON_A_FULL_DISK, "run", str(MISSIONS / "survey.plan"),
                             "--plain", "--output", str(tmp_path / "out")], capture_output=True, text=True,
                            timeout=RUN_S, cwd=tmp_path)
    assert result.returncode == 6, result.stderr
    records = read_log(tmp_path / "out" / "events.jsonl")
    unsaved = [r for r in records if r["kind"] == "photo_not_saved"]
    assert len(unsaved) == 1 and "No space left on device" in unsaved[0]["detail"], "said once"
    assert not [r for r in records if r["kind"] in ("FAILED", "WRONG_PROGRESS", "mission_failed")]
    assert not list((tmp_path / "out").glob("photo_*")), "no photo left half written"
    (touchdown,) = [r for r in records if r["kind"] == "drone_landed"]
    assert math.hypot(*touchdown["data"]["position"][:2]) < 2.0, "it flew the whole survey and landed at home"
    assert ended(records)["detail"] == "completed" and ended(records)["data"]["exit_status"] == 6
    last = result.stderr.strip().splitlines()[-1]
    assert last == "photos could not be saved (No space left on device): exit status 6", result.stderr


FAILING = """
import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    api.execute_behavior("GO_TO_POINT", coordinates=[4, 0, 3])
    raise RuntimeError("the mission gives up")
"""


@pytest.mark.parametrize("mission", ["failing.py", "figure10.py"])
def test_the_exit_status_is_the_one_the_last_line_and_run_ended_state_wherever_the_disk_fills(tmp_path, mission):
    source = tmp_path / mission
    source.write_text(FAILING if mission == "failing.py" else (MISSIONS / mission).read_text())

    def run(room: int, out: str) -> tuple[int, str, list[dict]]:
        result = subprocess.run([sys.executable, "-c", FULL_DISK, str(room), "run", str(source), "--plain",
                                 "--output", str(tmp_path / out)], capture_output=True, text=True, timeout=RUN_S,
                                cwd=tmp_path)
        assert "Traceback" not in result.stderr, result.stderr
        return result.returncode, result.stderr.strip().splitlines()[-1], read_log(tmp_path / out / "events.jsonl")

    code, last, records = run(10 ** 9, "whole0000")  # as long a name as the others
    whole = (tmp_path / "whole0000" / "events.jsonl").stat().st_size
    expected = 1 if mission == "failing.py" else 0
    assert code == expected and ended(records)["data"]["exit_status"] == expected
    for room in (whole // 3, whole - 400, whole - 150, whole - 1):  # the run's last records cut too
        code, last, records = run(room, f"{room:09d}")
        assert code == (1 if mission == "failing.py" else 6), (room, last)
        assert last.endswith(f": exit status {code}"), (room, last)
        stated = [r for r in records if r["kind"] == "run_ended"]
        assert not stated or stated[0]["data"]["exit_status"] == code, (room, stated)
        assert records[-1]["kind"] != "log_closed", room


NO_SPACE_AT_START = """
import errno, os, sqlite3, sys

if sys.argv[1] == "journal":  # SQLite finds the disk full when it makes the new journal
    class Full(sqlite3.Connection):
        def executescript(self, script):
            raise sqlite3.OperationalError("database or disk is full")

    connect = sqlite3.connect
    sqlite3.connect = lambda *args, **kwargs: connect(*args, **{**kwargs, "factory": Full})
else:  # the output folder's check finds it full
    from aeroexec.flight import output

    class FullDisk:
        def __getattr__(self, name):
            return getattr(os, name)

        def write(self, fd, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    output.os = FullDisk()
from aeroexec.cli.main import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("found_by", ["journal", "folder"])
def test_a_new_run_on_a_full_disk_is_refused_as_an_output_folder_with_no_space_left(tmp_path, found_by):
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, "-c", NO_SPACE_AT_START, found_by, "run", FIGURE10, "--plain",
                             "--output", str(out)], capture_output=True, text=True, timeout=RUN_S, cwd=tmp_path)
    assert result.returncode == 2, result.stderr  # an output folder that cannot be used, as a file in its way is
    assert f"the output folder {out} has no space left" in result.stderr
    assert "not a flight journal" not in result.stderr and "Traceback" not in result.stderr
    assert "activated" not in result.stdout, "nothing flew"


def test_a_closed_standard_output_ends_a_command_quietly(tmp_path):
    read, write = os.pipe()
    process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "catalog"], stdout=write,
                               stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    os.close(write)
    os.close(read)  # the reader is gone before anything is written
    _, err = process.communicate(timeout=60)
    assert process.returncode == 0 and err == ""


def test_catalog_piped_into_head_exits_0(tmp_path):
    result = subprocess.run(["bash", "-c", f"'{sys.executable}' -m aeroexec.cli.main catalog | head -1; "
                                           "exit ${PIPESTATUS[0]}"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stderr == "" and len(result.stdout.splitlines()) == 1


def test_a_closed_stdout_mid_flight_lets_the_flight_land(tmp_path):
    read, write = os.pipe()
    process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", FIGURE10, "--plain", "--output",
                                str(tmp_path / "out")], stdout=write, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    os.close(write)
    with os.fdopen(read) as events:
        assert events.readline()  # one event, then the reader goes away
    _, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    assert "Traceback" not in err and "internal error" not in err
    assert ended(read_log(tmp_path / "out" / "events.jsonl"))["detail"] == "completed"


def test_an_interrupt_while_the_loop_serves_the_mission_is_the_loops_not_the_missions():
    """Ctrl-C or SIGTERM may land while the loop's thread runs a request of the mission: it stays the loop's (the
    run aborts and lands), and the mission's call ends as aborted, not as a failure of the mission."""
    from aeroexec.drones.sim import SimulatedDrone, default_world
    from aeroexec.engine import api
    from aeroexec.engine.engine import Engine

    engine = Engine(SimulatedDrone(default_world()), obstacles=default_world())
    calls = []
    real = engine.memory.consult

    def consult(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt  # as the signal handler does, on the loop's thread
        return real(*args, **kwargs)

    engine.memory.consult = consult

    def mission() -> None:
        while True:
            api.consult_belief("flight_state(self, ?S)")
            api.wait(0.1)

    try:
        with pytest.raises(KeyboardInterrupt):
            engine.run(mission, max_time=10)
        engine.bridge.close()
        thread = engine._missions[0]
        thread.join(timeout=5)
        assert not thread.is_alive()
        assert not engine.log.events(kind="mission_failed")
    finally:
        engine.stop()


def test_a_signal_after_the_run_ended_leaves_its_exit_status_and_last_line(tmp_path, monkeypatch, capsys):
    """Found by the campaign (SIGTERM/SIGHUP/Ctrl-C sent to a real process at random times): a signal that came
    once the run had ended (while its summary was printed) made the process exit 130, 'aeroexec: interrupted',
    though run_ended said 'completed' with exit status 0."""
    from aeroexec.cli import run as run_command
    from aeroexec.cli.main import main

    printed = run_command.summary

    def summary_when_a_signal_comes(session, outcome):  # noqa: ANN001, ANN202
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C, as the run's own handler hears it
        return printed(session, outcome)

    monkeypatch.setattr(run_command, "summary", summary_when_a_signal_comes)
    status = main(["run", FIGURE10_TREE, "--plain", "--quiet", "--output", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 0, err
    assert "figure10.xml: completed at t=" in err and "interrupted" not in err
    assert ended(read_log(tmp_path / "out" / "events.jsonl"))["detail"] == "completed"
