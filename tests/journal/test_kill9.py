"""``kill -9`` for real: ``aeroexec run`` killed mid-mission (a tree, a Python mission, a QGroundControl plan; at two
points each), then ``aeroexec run --resume RUN_DIR``; over the two processes every goal is achieved once, as in an
uninterrupted run, photos included, and the drone ends landed where that run ends."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import pytest
from journeys import MISSIONS, achieved, final_state, fly, photos, same_goals, spec

RUN_S = 120.0  # s, wall: longest a run below may take


def run_and_kill(mission, folder, kind: str, count: int) -> None:
    """``aeroexec run MISSION``, killed with SIGKILL once its event log has ``count`` events of ``kind``."""
    process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--plain", "--quiet",
                                "--output", str(folder)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    log = folder / "events.jsonl"
    deadline = time.monotonic() + RUN_S
    try:
        while process.poll() is None and time.monotonic() < deadline:
            try:
                seen = log.read_text().count(f'"kind":"{kind}"')
            except OSError:
                seen = 0
            if seen >= count:
                os.kill(process.pid, signal.SIGKILL)
                break
            time.sleep(0.005)
    finally:
        if process.poll() is None and time.monotonic() >= deadline:
            process.kill()
        _, err = process.communicate(timeout=RUN_S)
    assert process.returncode == -signal.SIGKILL, f"the run was not killed mid-mission: {err.decode()[-2000:]}"


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The uninterrupted run of each mission, flown once."""
    runs = {}
    for mission in ("survey_legs.xml", "figure10.py", "survey.plan"):
        folder = tmp_path_factory.mktemp("whole") / mission
        _, outcome = fly(spec(MISSIONS / mission, folder))
        assert outcome.exit_status == 0
        runs[mission] = folder
    return runs


@pytest.mark.parametrize(("mission", "kind", "count"), [
    ("survey_legs.xml", "GOAL_ACHIEVED", 2),
    ("survey_legs.xml", "GOAL_ACHIEVED", 4),
    ("figure10.py", "activated", 2),
    ("figure10.py", "activated", 4),
    ("survey.plan", "photo_taken", 2),
    ("survey.plan", "photo_taken", 6),
], ids=["tree-early", "tree-late", "python-after-take-off", "python-way-back", "plan-early", "plan-mid-survey"])
def test_kill_9_mid_mission_then_resume(whole, tmp_path, mission, kind, count):
    whole = whole[mission]
    folder = tmp_path / "run"
    run_and_kill(MISSIONS / mission, folder, kind, count)
    resumed = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", "--resume", str(folder), "--plain",
                              "--quiet"], capture_output=True, text=True, timeout=RUN_S)
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    assert f"resuming {mission} from t=" in resumed.stderr
    difference = same_goals(achieved(folder), achieved(whole))
    assert difference is None, difference
    end, expected = final_state(folder), final_state(whole)
    assert end["landed_state"] == "on_ground" and not end["armed"]
    assert math.dist(end["position"], expected["position"]) < 1.0
    assert photos(folder) == photos(whole)
