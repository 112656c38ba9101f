"""A fleet's flights end as a run's do: Ctrl-C, SIGTERM and the time limit land every drone and wait for
touchdown; each drone's folder holds what a run's holds (event log with its status, ``.btlog``), plugins and
robot kinds reach every drone."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.cli.main import main
from flight_runs import MISSIONS, Command, ended, landed, read_log

TREE = MISSIONS / "figure10.xml"


def fleet_file(tmp_path: Path, mission: Path = TREE, count: int = 2) -> Path:
    drones = "\n".join(f"  - {{name: d{i}, mission: {mission}, home: [{3 * i}, 0]}}" for i in range(1, count + 1))
    path = tmp_path / "pair.yaml"
    path.write_text(f"fleet: pair\ndrones:\n{drones}\n")
    return path


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM], ids=["Ctrl-C", "SIGTERM"])
def test_an_interrupt_lands_every_drone_of_a_fleet(tmp_path, number):
    patrol = MISSIONS / "square_patrol.py"
    fleet = Command(tmp_path, "fleet", str(fleet_file(tmp_path, patrol)), "--plain", "--speed", "2", "--output",
                    str(tmp_path / "out"))
    fleet.wait_for("d1 | [")
    fleet.wait_for("GOAL_ACHIEVED TAKE_OFF")
    fleet.signal(number)
    code, out, err = fleet.finish()
    assert code == 1, err  # the missions did not complete
    assert "every drone aborts and lands" in err and "Traceback" not in err
    for drone in ("d1", "d2"):
        records = read_log(tmp_path / "out" / drone / "events.jsonl")
        assert ended(records)["detail"] == "aborted" and records[-1]["kind"] == "log_closed"
        assert landed(records), f"{drone} was left in the air"
    status = json.loads((tmp_path / "out" / "fleet_status.json").read_text())
    assert status["status"] == "aborted" and set(status["drones"]) == {"d1", "d2"}


def test_the_time_limit_lands_every_drone_of_a_fleet(tmp_path, capsys):
    code = main(["fleet", str(fleet_file(tmp_path, MISSIONS / "square_patrol.py")), "--quiet", "--max-time", "8",
                 "--output", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 1, err
    for drone in ("d1", "d2"):
        records = read_log(tmp_path / "out" / drone / "events.jsonl")
        assert any(r["kind"] == "engine_time_limit" for r in records)
        assert ended(records)["detail"] == "failed" and landed(records), drone
        assert f"{drone}: square_patrol.py failed" in err and "landed" in err


def test_a_fleet_drones_folder_holds_what_a_runs_folder_holds(tmp_path, capsys):
    assert main(["run", str(TREE), "--quiet", "--output", str(tmp_path / "alone")]) == 0
    assert main(["fleet", str(fleet_file(tmp_path)), "--quiet", "--output", str(tmp_path / "fleet")]) == 0
    alone = sorted(p.name for p in (tmp_path / "alone").iterdir())
    assert alone == ["events.jsonl", "journal.sqlite", "mission.btlog"]
    for drone in ("d1", "d2"):
        assert sorted(p.name for p in (tmp_path / "fleet" / drone).iterdir()) == alone
        records = read_log(tmp_path / "fleet" / drone / "events.jsonl")
        assert ended(records)["detail"] == "completed" and records[0]["drone_name"] == drone


def test_plugins_reach_every_drone_of_a_fleet(tmp_path):
    plugin = tmp_path / "weather_plugin.py"
    plugin.write_text("from aeroexec.beliefs import BeliefUpdater\n\n\n"
                      "class Weather(BeliefUpdater):\n"
                      "    def update(self, memory, now):\n"
                      "        memory.declare('wind', 1)\n"
                      "        memory.add('wind(calm)')\n\n\n"
                      "def updaters(drone):\n"
                      "    return [Weather('weather', period=60)]\n")
    result = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "fleet", str(fleet_file(tmp_path)), "--quiet",
                             "--updater", "weather_plugin:updaters", "--output", str(tmp_path / "out")],
                            capture_output=True, text=True, timeout=120, cwd=tmp_path,
                            env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert result.returncode == 0, result.stderr
    for drone in ("d1", "d2"):
        records = read_log(tmp_path / "out" / drone / "events.jsonl")
        assert any(r["kind"] == "belief_added" and r["belief"] == "wind(calm)" for r in records), drone
