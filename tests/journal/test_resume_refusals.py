"""A resume goes on with the run its folder holds, as it was flown, or it is refused before anything moves or is
written: a mission edited since (a tree's waypoint), a journal copied from another run's folder, a damaged journal,
times no run reaches. A refused resume exits 1 as a refused mission does, says which file and what, and leaves the
event log and the journal byte for byte as they were; the run then resumes as it was."""

from __future__ import annotations

import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.flight.journal.agreement import disagreements
from aeroexec.flight.journal.identity import changed_files
from journeys import MISSIONS, achieved, crash, final_state, fly_until, goals_after, resume, spec

RUN_S = 120.0  # s, wall: longest a resume below may take
OUTPUTS = ("events.jsonl", "journal.sqlite", "mission.btlog")


def aeroexec_resume(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", "--resume", str(folder), "--plain",
                           "--quiet"], capture_output=True, text=True, timeout=RUN_S)


def files(folder: Path) -> dict[str, bytes]:
    return {name: (folder / name).read_bytes() for name in OUTPUTS if (folder / name).exists()}


def refused(folder: Path, *said: str) -> str:
    """``aeroexec run --resume folder``, refused (exit 1, saying each of ``said``), leaving the run's files as they
    were; its message."""
    before = files(folder)
    result = aeroexec_resume(folder)
    assert result.returncode == 1, (result.returncode, result.stderr[-3000:])
    assert "Traceback" not in result.stderr and "please report" not in result.stderr, result.stderr[-3000:]
    for words in said:
        assert words in result.stderr, result.stderr[-3000:]
    assert files(folder) == before, "a refused resume changed the run's files"
    assert not (folder / "journal.sqlite.lock").exists()
    return result.stderr


@pytest.fixture
def legs(tmp_path):
    """survey_legs.xml, a copy of it, crashed (kill -9) after its first leg."""
    mission = tmp_path / "survey_legs.xml"
    shutil.copy(MISSIONS / "survey_legs.xml", mission)
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), goals_after(2)))
    return mission, folder


def test_a_tree_whose_waypoint_was_edited_is_refused_and_the_run_resumes_as_it_was(legs):
    mission, folder = legs
    flown = mission.read_text()
    mission.write_text(flown.replace('target="3, 3, 2"', 'target="5, 3, 2"'))  # the tree's shape is the same
    message = refused(folder, f"{mission}: the mission file changed since the interrupted run flew it")
    assert "aeroexec run" in message  # what to do: put it back, or fly it from its start
    assert changed_files(folder) == [f"{mission}: the mission file changed"]
    mission.write_text(flown)
    assert changed_files(folder) == []
    _, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    legs_flown = [a["COORDINATES"] for b, a in achieved(folder) if b == "GO_TO_POINT"]
    assert legs_flown == [[3, 0, 2], [3, 3, 2], [0, 0, 2]]  # never (5, 3, 2)


MAIN = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="sub/legs.xml"/>
  <BehaviorTree ID="Main"><Sequence><TAKE_OFF ALTITUDE="2"/><SubTree ID="Legs"/><LAND/></Sequence></BehaviorTree>
</root>
"""
LEGS = """<root BTCPP_format="4"><BehaviorTree ID="Legs"><Sequence>
  <GO_TO_POINT COORDINATES="3, 0, 2"/><GO_TO_POINT COORDINATES="3, 3, 2"/><GO_TO_POINT COORDINATES="0, 0, 2"/>
</Sequence></BehaviorTree></root>
"""


def test_a_tree_whose_included_file_was_edited_is_refused(tmp_path):
    mission, legs = tmp_path / "main.xml", tmp_path / "sub" / "legs.xml"
    mission.write_text(MAIN)
    legs.parent.mkdir()
    legs.write_text(LEGS)
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), goals_after(2)))
    legs.write_text(LEGS.replace("3, 3, 2", "5, 3, 2"))
    refused(folder, f"{legs}: the included file changed since the interrupted run flew it")


def test_a_journal_whose_tree_state_does_not_fit_is_refused_without_a_write(legs):
    _, folder = legs
    with sqlite3.connect(folder / "journal.sqlite") as db:
        db.execute("UPDATE meta SET value = json_remove(value, '$[3]') WHERE key = 'tree_shape'")
    refused(folder, "it is not the tree the interrupted run flew")


def test_a_rules_file_changed_since_is_refused(tmp_path):
    rules = tmp_path / "rules.pl"
    rules.write_text("near_home(?X) :- position(?X, ?P).\n")
    folder = tmp_path / "run"
    crash(fly_until(spec(MISSIONS / "survey_legs.xml", folder, rules=(str(rules),)), goals_after(2)))
    rules.write_text("near_home(?X) :- speed(?X, ?P).\n")
    refused(folder, f"{rules}: the rules file changed since the interrupted run flew it")


def test_a_journal_copied_from_another_runs_folder_is_refused(legs, tmp_path):
    _, folder = legs
    other = tmp_path / "other"
    crash(fly_until(spec(MISSIONS / "figure10.py", other), goals_after(2)))
    shutil.copy(folder / "journal.sqlite", other / "journal.sqlite")  # beside figure10's event log
    run = sqlite3.connect(folder / "journal.sqlite").execute("SELECT value FROM meta WHERE key = 'run'").fetchone()[0]
    assert run.startswith("run-")
    message = refused(other, f"the journal is of run {run}", "copied from another run's folder")
    assert str(folder) in message  # where it was flown
    alone = tmp_path / "alone"
    alone.mkdir()
    shutil.copy(folder / "journal.sqlite", alone / "journal.sqlite")  # no event log beside it
    refused(alone, f"flown in {folder}, not in this folder")


def test_a_run_folder_moved_whole_resumes(legs, tmp_path):
    _, folder = legs
    moved = tmp_path / "moved"
    folder.rename(moved)
    _, outcome = resume(moved)
    assert outcome.exit_status == 0, outcome.status
    assert final_state(moved)["landed_state"] == "on_ground"


@pytest.mark.parametrize(("damage", "said"), [
    ("UPDATE meta SET value = json_remove(value, '$.robot') WHERE key = 'spec'", "does not say its robot"),
    ("UPDATE meta SET value = json_remove(value, '$.drone', '$.robot') WHERE key = 'spec'",
     "does not say its robot or drone"),
    ("UPDATE meta SET value = '[1, 2]' WHERE key = 'spec'", "does not say what flight it was"),
    ("UPDATE meta SET value = json_set(value, '$.seed', 'x') WHERE key = 'spec'", "cannot be read"),
    ("DELETE FROM meta WHERE key = 'run'", "does not say which run it is"),
    ("DELETE FROM meta WHERE key = 'files'", "does not say which files shaped its flight"),
], ids=["no-robot", "no-drone-no-robot", "spec-not-a-flight", "seed-not-a-number", "no-run", "no-files"])
def test_a_damaged_journal_is_refused_naming_the_journal_and_what_is_missing(legs, damage, said):
    _, folder = legs
    with sqlite3.connect(folder / "journal.sqlite") as db:
        db.execute(damage)
    message = refused(folder, said)
    assert f"{folder / 'journal.sqlite'}: " in message


@pytest.mark.parametrize("time", [1e300, float("inf"), 1e9])
def test_an_implausible_last_time_is_refused_and_nothing_takes_off(legs, time):
    _, folder = legs
    with sqlite3.connect(folder / "journal.sqlite") as db:
        db.execute("UPDATE events SET time = ? WHERE seq = (SELECT max(seq) FROM events)", (time,))
    refused(folder, f"{folder / 'journal.sqlite'}: the journal is damaged: its last time is t=",
            "not a time a run reaches")


def test_an_implausible_place_is_refused(legs):
    _, folder = legs
    with sqlite3.connect(folder / "journal.sqlite") as db:
        db.execute("UPDATE events SET record = json_set(record, '$.position[2]', 1e300) WHERE kind = 'state'")
    refused(folder, f"{folder / 'journal.sqlite'}: the journal is damaged: the drone's place")


def test_an_implausible_time_in_the_event_log_is_refused(legs):
    _, folder = legs
    log = folder / "events.jsonl"
    with open(log, "a") as file:
        file.write('{"time":1e300,"kind":"state"}\n')
    refused(folder, f"{log}: the event log is damaged: its last record is t=1e+300 s")


def test_a_resumed_run_agrees_with_its_event_log(legs):
    _, folder = legs
    _, outcome = resume(folder)
    assert outcome.exit_status == 0
    assert disagreements(folder) == []


def test_a_vehicle_profile_changed_since_is_refused(tmp_path):
    """The profile bounds the route, the simulator and the safety rules: a resume with another endurance or
    ceiling would fly the rest of the mission by figures it was not verified with."""
    profile = tmp_path / "hexacopter.yaml"
    profile.write_text("endurance: 75\nceiling: 120\n")
    folder = tmp_path / "run"
    crash(fly_until(spec(MISSIONS / "survey_legs.xml", folder, vehicle=str(profile)), goals_after(2)))
    profile.write_text("endurance: 75\nceiling: 40\n")
    refused(folder, f"{profile}: the vehicle profile file changed since the interrupted run flew it")
