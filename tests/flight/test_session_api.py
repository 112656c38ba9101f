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
