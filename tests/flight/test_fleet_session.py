"""The fleet session as an embedder uses it, as ``aeroexec fleet`` does: a loaded fleet file and the flight every
drone shares in, the whole fleet set up (output folder, token, the fleet's router, ``fleet.json`` for ``ctl
--fleet``, every drone's session), flown and closed in one place."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from aeroexec.fleet.fleet_file import load_fleet
from aeroexec.flight import FleetSession, FlightError, FlightSpec, fleet_exit_status
from flight_runs import MISSIONS, ROOT, ended, read_log


def pair(tmp_path: Path) -> Path:
    path = tmp_path / "pair.yaml"
    path.write_text("fleet: pair\ntoken: pair-token\ndrones:\n"
                    f"  - {{name: d1, mission: {MISSIONS / 'figure10.xml'}, home: [0, 0]}}\n"
                    f"  - {{name: d2, mission: {MISSIONS / 'figure10.xml'}, home: [3, 0]}}\n")
    return path


def test_a_fleet_session_sets_the_whole_fleet_up_flies_it_and_closes_it(tmp_path):
    file = pair(tmp_path)
    out = tmp_path / "out"
    told = []
    with FleetSession(load_fleet(file), FlightSpec(mission=file), output=out, notify=told.append) as fleet:
        link = json.loads((out / "fleet.json").read_text())  # ctl --fleet reaches the drones while they fly
        assert link["token"] == "pair-token" and link["endpoints"] == fleet.endpoints and fleet.endpoints
        assert link["drones"] == ["d1", "d2"] and sorted(fleet.flight.engines) == ["d1", "d2"]
        drones = fleet.fly()
    assert list(drones) == ["d1", "d2"] and fleet_exit_status(drones) == 0
    for name, record in drones.items():
        assert record["status"] == "completed" and record["summary"].startswith(f"{name}: figure10.xml completed")
        assert ended(read_log(out / name / "events.jsonl"))["detail"] == "completed"
    status = json.loads((out / "fleet_status.json").read_text())
    assert status["status"] == "completed" and set(status["drones"]) == {"d1", "d2"}
    assert not (out / "fleet.json").exists()  # the fleet is over: nothing to reach


def test_a_fleet_that_cannot_be_set_up_says_why_and_leaves_nothing_open(tmp_path):
    file = pair(tmp_path)
    (tmp_path / "taken").write_text("a file, not a folder")
    fleet = FleetSession(load_fleet(file), FlightSpec(mission=file), output=tmp_path / "taken")
    with pytest.raises(FlightError, match="taken: not a folder") as refused:
        fleet.open()
    assert refused.value.usage and fleet.membership is None and fleet.flight is None
    fleet.close()  # again: nothing to do


def test_a_fleet_whose_mission_cannot_fly_closes_its_router_and_its_fleet_file(tmp_path):
    broken = tmp_path / "broken.xml"
    broken.write_text("<root BTCPP_format='4'><BehaviorTree ID='M'><NO_SUCH_BEHAVIOR/></BehaviorTree></root>\n")
    file = tmp_path / "pair.yaml"
    file.write_text(f"fleet: pair\ndrones:\n  - {{name: d1, mission: {broken}}}\n")
    fleet = FleetSession(load_fleet(file), FlightSpec(mission=file), output=tmp_path / "out",
                         report=lambda problem: None)
    with pytest.raises(FlightError):
        fleet.open()
    assert fleet.membership is not None and not (tmp_path / "out" / "fleet.json").exists()
    assert fleet.membership.session.is_closed()


def test_the_embedding_page_flies_a_fleet_as_written(tmp_path, monkeypatch, capsys):
    page = (ROOT / "docs" / "embedding.md").read_text()
    snippet, = [block for block in re.findall(r"```python\n(.*?)```", page, re.S) if "FleetSession" in block]
    (tmp_path / "missions").mkdir()
    for name in ("relay.yaml", "relay_scout.py", "relay_carrier.py"):
        shutil.copy(MISSIONS / name, tmp_path / "missions" / name)
    monkeypatch.chdir(tmp_path)  # the page's paths are the repository's; its output folder is made here
    exec(compile(snippet, "embedding.md", "exec"), {"__name__": "embedding_page"})
    status, *summaries = capsys.readouterr().out.splitlines()
    assert status == "0" and [line.split(":")[0] for line in summaries] == ["scout", "carrier"]
    assert all(" completed at " in line for line in summaries), summaries
