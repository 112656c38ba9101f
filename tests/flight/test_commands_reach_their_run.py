"""``aeroexec ctl`` acts on the run it means: alone, the one live run; with several, none (they are listed);
every answer names its run; a run is listed from the moment it starts, and ``abort`` gives up its start."""

from __future__ import annotations

import subprocess
import sys

import pytest
from flight_runs import MISSIONS, Command, ended, read_log
from free_ports import free_udp_port

PATROL = str(MISSIONS / "square_patrol.py")


def ctl(cwd, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "ctl", *args], capture_output=True, text=True,
                          timeout=60, cwd=cwd)


def test_with_two_live_runs_ctl_refuses_and_names_both(tmp_path):
    runs = [Command(tmp_path, "run", PATROL, "--plain", "--speed", "3", "--output", str(tmp_path / name))
            for name in ("first", "second")]
    try:
        for run in runs:
            run.wait_for("GOAL_ACHIEVED TAKE_OFF")
        refused = ctl(tmp_path, "abort")
        assert refused.returncode == 2, refused.stderr
        assert "2 live runs: name one with --run DIR|PID (nothing was sent)" in refused.stderr
        for run, name in zip(runs, ("first", "second"), strict=True):
            assert f"pid {run.process.pid}" in refused.stderr and str(tmp_path / name) in refused.stderr
        # the second run holds until it is aborted: at 3x it would otherwise finish its patrol on a loaded machine
        # before the first is done with (seen: "no live run found")
        held = ctl(tmp_path, "pause", "--run", str(runs[1].process.pid))
        assert held.returncode == 0, held.stderr
        aborted = ctl(tmp_path, "abort", "--run", str(runs[0].process.pid))
        assert aborted.returncode == 0, aborted.stderr
        assert aborted.stdout.startswith(f"square_patrol.py (pid {runs[0].process.pid}, {tmp_path / 'first'}): ")
        assert runs[0].finish()[0] == 4
        alone = ctl(tmp_path, "abort")  # one live run left: it is the one meant
        assert alone.returncode == 0 and f"pid {runs[1].process.pid}" in alone.stdout
        assert runs[1].finish()[0] == 4
    finally:
        for run in runs:
            run.process.kill()
    for name in ("first", "second"):
        assert ended(read_log(tmp_path / name / "events.jsonl"))["detail"] == "aborted"


@pytest.mark.mavsdk
def test_a_run_is_listed_while_it_starts_and_abort_gives_the_start_up(tmp_path):
    port = free_udp_port()  # no vehicle there: the run waits for one
    run = Command(tmp_path, "run", PATROL, "--plain", "--drone", f"mavsdk:udpin://127.0.0.1:{port}",
                  "--output", str(tmp_path / "out"))
    try:
        run.wait_for("waiting up to")
        listed = ctl(tmp_path, "list")
        assert listed.returncode == 0 and f"pid {run.process.pid}" in listed.stdout
        status = ctl(tmp_path, "status")
        assert status.returncode == 0 and "the run is waiting for its vehicle" in status.stdout
        refused = ctl(tmp_path, "pause")
        assert refused.returncode == 1 and "can be sent once it flies" in refused.stderr
        aborted = ctl(tmp_path, "abort")
        assert aborted.returncode == 0 and "start is given up" in aborted.stdout
        code, _, err = run.finish(timeout=30)
    finally:
        run.process.kill()
    assert code == 1 and "the start was aborted while waiting for the vehicle" in err
    assert "Traceback" not in err
