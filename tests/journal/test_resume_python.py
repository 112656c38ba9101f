"""Python missions resumed by deterministic replay: the mission runs again from the top, its journaled calls answer
at once without acting, and it goes live at the first call the journal has no result for. A mission file edited
since is refused before anything moves; a mission whose calls differ on the resume (it reads something that
changed) is refused at the call where it diverges, with its line."""

from __future__ import annotations

import math
import shutil

import pytest
from aeroexec.flight.journal import Journal
from aeroexec.flight.spec import FlightError
from journeys import (
    MISSIONS,
    achieved,
    active,
    crash,
    final_state,
    fly,
    fly_until,
    goals_after,
    resume,
    same_goals,
    spec,
)

FIGURE10 = MISSIONS / "figure10.py"
HOME = MISSIONS.parent / "tests" / "changes" / "data" / "patrol_home.xml"  # a tree a flying drone may load


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    folder = tmp_path_factory.mktemp("whole")
    _, outcome = fly(spec(FIGURE10, folder))
    assert outcome.exit_status == 0
    return folder


@pytest.mark.parametrize("point", [goals_after(1), active("GO_TO_POINT", 1.0), goals_after(3), active("LAND", 0.5)],
                         ids=["after-take-off", "first-go-to", "after-both-go-tos", "landing"])
def test_a_python_mission_crashed_mid_mission_resumes_by_replay(whole, tmp_path, point):
    folder = tmp_path / "run"
    crash(fly_until(spec(FIGURE10, folder), point))
    with Journal(folder) as journal:
        before = journal.rows("SELECT count(*) FROM calls WHERE returned_at IS NOT NULL")[0][0]
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    difference = same_goals(achieved(folder), achieved(whole))
    assert difference is None, difference
    end, expected = final_state(folder), final_state(whole)
    assert end["landed_state"] == "on_ground" and math.dist(end["position"], expected["position"]) < 1.0
    recorder = session.engine.bridge.recorder
    assert recorder.count == 7 and len(recorder.replay) >= before  # every call kept was replayed, not made again
    with Journal(folder) as journal:  # one kept result per call of the mission, over both parts
        numbers = [r[0] for r in journal.rows("SELECT number FROM calls WHERE superseded = 0 UNION ALL "
                                              "SELECT first FROM looks WHERE superseded = 0 ORDER BY 1")]
    assert numbers == list(range(1, 8))


def test_replayed_calls_do_not_act(tmp_path):
    folder = tmp_path / "run"
    crash(fly_until(spec(FIGURE10, folder), goals_after(3)))  # TAKE_OFF and both GO_TO_POINTs done
    session, outcome = resume(folder)
    assert outcome.exit_status == 0
    started = [e.behavior for e in session.engine.log.events("activated") if e.data.get("source") == "mission"]
    assert "TAKE_OFF" not in started and "GO_TO_POINT" not in started
    assert started[-1] == "LAND"


def varying(tmp_path, monkeypatch, old: str, new: str):
    """figure10.py whose ``old`` code becomes ``new`` when the environment says EDITED: the same file (a file edited
    since is refused whole), calls that differ on the resume (a mission that reads the world, a clock, a file)."""
    mission = tmp_path / "figure10.py"
    imported = "import aeroexec.engine.api as api"
    source = FIGURE10.read_text().replace(imported, f"{imported}; import os")  # the lines stay where they were
    mission.write_text(source.replace(old, new))
    return mission, lambda: monkeypatch.setenv("EDITED", "1")


def test_a_mission_whose_calls_differ_is_refused_at_the_line_where_it_diverges(tmp_path, monkeypatch):
    mission, edit = varying(tmp_path, monkeypatch, "point=[2, 5, 1.3]",
                            "point=[3, 5, 1.3] if os.environ.get('EDITED') else [2, 5, 1.3]")
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), active("GO_TO_POINT", 1.0)))  # the edited call under way
    edit()
    session, outcome = resume(folder)
    assert outcome.exit_status == 1
    reason = outcome.status.reasons[0]
    assert "figure10.py:20" in reason and "differs from the interrupted run at its call 4" in reason, reason
    assert "point=[3, 5, 1.3]" in reason and "point=[2, 5, 1.3]" in reason, reason
    assert not [e for e in session.engine.log.events("activated") if e.data.get("source") in ("mission", "resume")]
    # the refusal changed nothing: resumed with the mission as it was, it goes on
    monkeypatch.delenv("EDITED")
    _, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status


def test_calls_that_differ_before_the_resume_point_are_refused_too(tmp_path, monkeypatch):
    mission, edit = varying(tmp_path, monkeypatch, 'api.executeBehavior("TAKE_OFF")',
                            'api.executeBehavior("TAKE_OFF", **({"altitude": 3} if os.environ.get("EDITED") else {}))')
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), goals_after(3)))
    edit()
    _, outcome = resume(folder)
    assert outcome.exit_status == 1
    assert "figure10.py:11: the mission differs from the interrupted run at its call 1" in outcome.status.reasons[0]


def test_a_mission_that_ends_before_its_journaled_calls_is_refused(tmp_path, monkeypatch):
    mission, edit = varying(tmp_path, monkeypatch, "    api.inhibitBehavior",
                            "    if os.environ.get('EDITED'):\n        return\n    api.inhibitBehavior")
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), active("LAND", 0.5)))
    edit()
    _, outcome = resume(folder)
    assert outcome.exit_status == 1
    assert "the mission ended after 5 calls" in outcome.status.reasons[0], outcome.status.reasons


def test_an_edited_mission_file_is_refused_before_anything_moves(tmp_path):
    mission = tmp_path / "figure10.py"
    shutil.copy(FIGURE10, mission)
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), active("GO_TO_POINT", 1.0)))
    mission.write_text(FIGURE10.read_text().replace("point=[2, 5, 1.3]", "point=[3, 5, 1.3]"))
    with pytest.raises(FlightError, match="figure10.py: the mission file changed since the interrupted run flew it"):
        resume(folder)


POLLING = """import aeroexec.engine.api as api

def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    for corner in [(0, -12, 3), (8, -12, 3), (8, -16, 3)]:
        api.activate_behavior("GO_TO_POINT", coordinates=corner)
        while api.is_active_behavior("GO_TO_POINT"):
            api.true_belief("charge(battery, ?C), ?C > 20")
        api.execute_behavior("TAKE_PHOTO")
    api.execute_behavior("LAND")
"""


def test_a_polling_mission_replays_its_looks_and_goes_on(tmp_path):
    """Thousands of polling calls are kept as runs of looks (a few bytes) and replayed in order: the loop ends
    where it ended, the flown corners are not flown again."""
    mission = tmp_path / "polling.py"
    mission.write_text(POLLING)
    whole = tmp_path / "whole"
    _, outcome = fly(spec(mission, whole))
    assert outcome.exit_status == 0
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), goals_after(3)))  # TAKE_OFF, a corner, its photo: polling the next
    with Journal(folder) as journal:
        (looked,) = journal.rows("SELECT sum(count) FROM looks")[0]
        (rows,) = journal.rows("SELECT count(*) FROM looks")[0]
    assert looked > 100 and rows <= 3
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    assert session.engine.bridge.recorder.count > looked
    difference = same_goals(achieved(folder), achieved(whole))
    assert difference is None, difference
    corners = [e.data["arguments"]["COORDINATES"] for e in session.engine.log.events("activated", "GO_TO_POINT")
               if e.data.get("source") == "mission"]
    assert (0, -12, 3) not in corners


AEROSTACK2 = """import rclpy
from as2_python_api.drone_interface import DroneInterface


def mission():
    rclpy.init()
    uav = DroneInterface("drone0", verbose=False)
    uav.arm()
    uav.offboard()
    uav.takeoff(3.0, 1.0)
    uav.go_to(0, -12, 3, 2.0)
    uav.go_to(8, -12, 3, 2.0)
    uav.land(0.5)
"""


def test_an_aerostack2_mission_is_refused_for_resume_rather_than_flown_again(tmp_path):
    """Aerostack2's Python API drives behaviors without the journaled calls: a resume would fly the done legs
    again, so it is refused before anything moves, naming the file and the import."""
    mission = tmp_path / "as2_legs.py"
    mission.write_text(AEROSTACK2)
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), active("GO_TO_POINT", 1.0)))
    with pytest.raises(FlightError, match=r"as2_legs.py:2: a mission flown through Aerostack2's Python API"):
        resume(folder)


def test_a_program_replaced_in_flight_is_refused_for_resume(tmp_path):
    """A mission loaded in place of the Python mission (``ctl load``) is not the program the journal's calls are
    of: the resume is refused, saying so, rather than replaying one program's calls against another."""
    folder = tmp_path / "run"
    run = fly_until(spec(FIGURE10, folder), active("GO_TO_POINT", 1.0))
    ticket = run.engine.supervisor.submit("load", str(HOME), origin="test")
    run.engine.step(run.engine.period)
    assert ticket.result is not None and ticket.result.ok, ticket.result
    assert run.engine.run_until(lambda: active("GO_TO_POINT", 1.0)(run), 60.0)
    crash(run)
    with pytest.raises(FlightError, match=r"the mission was replaced in flight at t=.* \(load .*patrol_home.xml\)"):
        resume(folder)
