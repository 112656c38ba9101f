"""A Python mission changed while it flies: skip stops the behavior it waits for and its call returns INTERRUPTED
(the program decides what comes next); its items cannot be edited; a new mission of any format loaded into the
flight replaces any mission, checked from where the drone is."""

from __future__ import annotations

from pathlib import Path

from changing import DATA, MISSIONS, ChangedFlight, changes, ended, statuses

PROGRAM = '''import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", ALTITUDE=3)
    outcome = api.execute_behavior("GO_TO_POINT", COORDINATES=(10, 0, 3))
    with open({said!r}, "a") as said:
        said.write(f"first flight: {{outcome}}\\n")
    api.execute_behavior("GO_TO_POINT", COORDINATES=(0, -4, 3))
    with open({said!r}, "a") as said:
        said.write("second flight done\\n")
    api.execute_behavior("LAND")
'''


def program(tmp_path) -> tuple[Path, Path]:
    said = tmp_path / "said.txt"
    path = tmp_path / "program.py"
    path.write_text(PROGRAM.format(said=str(said)), encoding="utf-8")
    return path, said


def flying_to_the_first_point(tmp_path) -> tuple[ChangedFlight, Path]:
    path, said = program(tmp_path)
    flight = ChangedFlight(path, tmp_path / "run")
    flight.until(lambda: flight.active("GO_TO_POINT"))
    flight.engine.step(1.0)
    return flight, said


def test_skip_ends_the_behavior_a_program_waits_for_and_its_call_returns_interrupted(tmp_path):
    flight, said = flying_to_the_first_point(tmp_path)
    now = flight.engine.now()
    result = flight.change("skip")
    assert result.ok and result.message == ("GO_TO_POINT skipped; the mission's call returns INTERRUPTED (skipped "
                                            "by the operator)")
    records = flight.finish()
    assert said.read_text().splitlines() == ["first flight: INTERRUPTED", "second flight done"]
    assert flight.closest((10.0, 0.0, 3.0), after=now) > 3.0
    interrupted = [r for r in records if r["kind"] == "INTERRUPTED" and r["behavior"] == "GO_TO_POINT"]
    assert interrupted[0]["detail"] == "skipped by the operator"
    assert ended(records) == "completed"


def test_a_program_cannot_be_edited_while_it_runs_and_says_so(tmp_path):
    flight, _ = flying_to_the_first_point(tmp_path)
    for command, argument in [("jump", "2"), ("insert", "after 1 LAND"), ("delete", "2"), ("items", "")]:
        result = flight.change(command, argument)
        assert not result.ok
    assert result.message == "the mission has no items to list (a Python program, or none running)"
    assert changes(flight.finish())[0]["detail"] == (
        "jump 2: refused: a Python mission is a program: its items cannot be changed while it runs (skip skips the "
        "behavior it waits for; load flies a new mission)")


def test_a_tree_loaded_into_a_flying_program_replaces_it_and_flies(tmp_path):
    flight, said = flying_to_the_first_point(tmp_path)
    result = flight.change("load", str(DATA / "patrol_home.xml"))
    assert result.ok and result.message == "patrol_home.xml loaded in place of the running mission"
    records = flight.finish()
    assert not said.exists()  # the program was stopped where it waited: none of its later lines ran
    kinds = [r["kind"] for r in records if r["kind"].startswith("mission_")]
    assert kinds == ["mission_started", "mission_replaced", "mission_change", "mission_started",
                     "mission_completed"]
    assert statuses(records, "home") == ["RUNNING", "SUCCESS"]
    assert ended(records) == "completed"
    assert sorted(p.name for p in (flight.session.folder / "loaded").iterdir()) == ["1-patrol_home.xml"]
    assert (flight.session.folder / "mission-2.btlog").is_file()


def test_a_program_loaded_into_a_flying_tree_replaces_it_and_a_load_that_cannot_fly_from_here_is_refused(
        tmp_path):
    path, said = program(tmp_path)
    path.write_text(path.read_text().replace('    api.execute_behavior("TAKE_OFF", ALTITUDE=3)\n', ""))
    flight = ChangedFlight(DATA / "patrol.xml", tmp_path / "run")
    flight.until(lambda: flight.running("corner B"))
    again = flight.change("load", str(DATA / "patrol.xml"))  # it takes off first: the drone flies
    assert not again.ok and again.message.endswith(
        "patrol.xml:7: The execution of behavior TAKE_OFF cannot be done after the execution of GO_TO_POINT (flight "
        "is moving; TAKE_OFF needs landed)")
    broken = flight.change("load", str(MISSIONS / "nowhere.py"))
    assert not broken.ok and "nowhere.py" in broken.message
    assert flight.change("load", str(path)).ok
    records = flight.finish()
    assert said.read_text().splitlines() == ["first flight: GOAL_ACHIEVED", "second flight done"]
    assert [r["detail"] for r in records if r["kind"] == "mission_replaced"] == [
        "patrol.xml: halted (program.py was loaded in its place)"]
    assert ended(records) == "completed"
