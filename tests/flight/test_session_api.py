"""The flight session as an embedder uses it: a FlightSpec in, a flight out, its files where a run's go; the same
for a robot of another kind (the rover of examples/rover, through its robot kind)."""

from __future__ import annotations

from pathlib import Path

import pytest
from aeroexec.flight import FlightError, FlightSession, FlightSpec
from flight_runs import ROOT, ended, read_log


def test_a_session_flies_a_rover_mission_and_leaves_a_runs_files(tmp_path):
    spec = FlightSpec(mission=ROOT / "examples" / "rover" / "missions" / "patrol.xml", robot="rover",
                      output=str(tmp_path / "out"), register=False)
    with FlightSession(spec, notify=lambda text: None) as session:
        outcome = session.fly()
    assert (outcome.status.word, outcome.exit_status) == ("completed", 0)
    assert sorted(p.name for p in outcome.folder.iterdir()) == ["events.jsonl", "journal.sqlite", "mission.btlog"]
    records = read_log(outcome.folder / "events.jsonl")
    assert records[0]["robot"] == "rover" and ended(records)["detail"] == "completed"


def test_a_session_that_cannot_fly_says_why_and_leaves_nothing_running(tmp_path):
    spec = FlightSpec(mission=Path(tmp_path / "missing.py"), output=str(tmp_path / "out"), register=False)
    session = FlightSession(spec, notify=lambda text: None)
    with pytest.raises(FlightError, match="missing.py"):
        session.open()
    assert session.engine is None


RULES = "airborne(?D) :- flight_state(?D, flying).\nairborne(?D) :- flight_state(?D, hovering).\n"
TREE = """<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>
  <TAKE_OFF/>
  <CheckBelief belief="airborne(self)"/>
  <LAND/>
</Sequence></BehaviorTree></root>
"""


def test_a_rules_file_given_to_run_and_fleet_reaches_every_flight(tmp_path):
    from aeroexec.cli.main import main

    (tmp_path / "air.rules").write_text(RULES)
    (tmp_path / "m.xml").write_text(TREE)
    (tmp_path / "pair.yaml").write_text(f"fleet: pair\ndrones:\n  - {{name: a, mission: {tmp_path / 'm.xml'}}}\n"
                                        f"  - {{name: b, mission: {tmp_path / 'm.xml'}, home: [4, 0]}}\n")
    assert main(["run", str(tmp_path / "m.xml"), "--quiet", "--output", str(tmp_path / "without")]) == 1  # unknown
    assert main(["run", str(tmp_path / "m.xml"), "--quiet", "--rules", str(tmp_path / "air.rules"),
                 "--output", str(tmp_path / "run")]) == 0
    assert main(["fleet", str(tmp_path / "pair.yaml"), "--quiet", "--rules", str(tmp_path / "air.rules"),
                 "--output", str(tmp_path / "fleet")]) == 0
