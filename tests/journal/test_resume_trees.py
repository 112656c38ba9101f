"""Tree missions (BehaviorTree.CPP XML with subtrees, scripts and a switch; a QGroundControl plan; TML) crashed
mid-mission at several points and resumed: every goal is achieved exactly once over the two parts of the run, as
in an uninterrupted run, photos included, and the drone ends landed where the uninterrupted run ends."""

from __future__ import annotations

import math

import pytest
from aeroexec.flight.journal import Journal
from journeys import (
    LIMIT,
    MISSIONS,
    achieved,
    active,
    crash,
    final_state,
    fly,
    fly_until,
    goals_after,
    photos,
    resume,
    same_goals,
    spec,
)


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The uninterrupted runs, each mission once."""
    runs = {}
    for name in ("survey_legs.xml", "survey.plan", "search_for_object.tml.xml"):
        folder = tmp_path_factory.mktemp("whole") / name
        _, outcome = fly(spec(MISSIONS / name, folder))
        assert outcome.exit_status == 0, outcome.status
        runs[name] = folder
    return runs


def check_resumed(folder, whole_folder):
    difference = same_goals(achieved(folder), achieved(whole_folder))
    assert difference is None, difference
    end, expected = final_state(folder), final_state(whole_folder)
    assert end["landed_state"] == "on_ground" and not end["armed"]
    assert math.dist(end["position"], expected["position"]) < 1.0, (end["position"], expected["position"])


@pytest.mark.parametrize(("mission", "point"), [
    ("survey_legs.xml", active("GO_TO_POINT", 1.0)),  # in the first leg's subtree
    ("survey_legs.xml", goals_after(3)),  # after the second leg, before the detour is skipped
    ("survey.plan", goals_after(7)),  # mid-survey, between a waypoint and its photo
    ("survey.plan", active("GO_TO_POINT", 2.0)),  # flying the first leg
    ("search_for_object.tml.xml", goals_after(1)),
], ids=["xml-first-leg", "xml-after-second-leg", "plan-after-7-goals", "plan-first-leg", "tml"])
def test_a_tree_crashed_mid_mission_resumes_and_achieves_every_goal_once(whole, tmp_path, mission, point):
    folder = tmp_path / "run"
    crash(fly_until(spec(MISSIONS / mission, folder), point))
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    check_resumed(folder, whole[mission])
    if mission.endswith(".plan"):
        assert photos(folder) == photos(whole[mission]) > 0  # no photo retaken, none missing
    assert session.journal is None or session.journal.segment == 2


def test_the_resumed_tree_goes_on_from_its_blackboard_and_memory(whole, tmp_path):
    """survey_legs.xml counts its legs in a Script (legs += 1) and checks the count at the end: resumed after the
    first leg, the count goes on from 1, and the done leg is not flown again."""
    folder = tmp_path / "run"
    crash(fly_until(spec(MISSIONS / "survey_legs.xml", folder), goals_after(2)))
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    flown = [activation["arguments"]["COORDINATES"] for activation in
             (event.data for event in session.engine.log.events("activated", "GO_TO_POINT"))
             if activation.get("source") == "mission"]
    assert flown == [(3, 3, 2), (0, 0, 2)]  # the second leg and the way home; not the first leg again
    assert session.tree.blackboard["legs"] == 2


ROUNDS = """<root BTCPP_format="4" main_tree_to_execute="Rounds"><BehaviorTree ID="Rounds"><Sequence>
  <TAKE_OFF ALTITUDE="3"/>
  <Repeat num_cycles="2"><Sequence>
    <GO_TO_POINT COORDINATES="0, -12, 3"/><TAKE_PHOTO/><BROADCAST_MESSAGE MESSAGE="corner 1"/>
    <GO_TO_POINT COORDINATES="8, -12, 3"/><TAKE_PHOTO/><BROADCAST_MESSAGE MESSAGE="corner 2"/>
  </Sequence></Repeat>
  <GO_TO_POINT COORDINATES="0, 0, 3"/><LAND/>
</Sequence></BehaviorTree></root>"""


@pytest.mark.parametrize("point", [goals_after(3, "TAKE_PHOTO"), goals_after(2, "BROADCAST_MESSAGE"),
                                   goals_after(7)], ids=["after-a-photo", "after-a-broadcast", "second-round"])
def test_photos_and_broadcasts_are_not_done_twice(tmp_path, point):
    mission = tmp_path / "rounds.xml"
    mission.write_text(ROUNDS)
    whole = tmp_path / "whole"
    _, outcome = fly(spec(mission, whole))
    assert outcome.exit_status == 0
    folder = tmp_path / "run"
    crash(fly_until(spec(mission, folder), point))
    _, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    check_resumed(folder, whole)
    assert photos(folder) == photos(whole) == 4
    with Journal(folder) as journal, Journal(whole) as once:
        sent = [r["detail"] for r in journal.rows("SELECT detail FROM events WHERE kind = 'message_sent'")]
        expected = [r["detail"] for r in once.rows("SELECT detail FROM events WHERE kind = 'message_sent'")]
    assert sent == expected and len(sent) == 4  # the Repeat's count came back: two rounds, not three


def test_the_rules_a_tree_added_are_the_resumed_memorys_too(tmp_path):
    """An AddRule done before the crash is not ticked again (its sequence skips it): its rules are added again."""
    mission = tmp_path / "rules.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>'
                       '<AddRule rule="charged(self) :- charge(battery, ?C), ?C &gt; 50."/><TAKE_OFF ALTITUDE="3"/>'
                       '<GO_TO_POINT COORDINATES="0, -12, 3"/><CheckBelief belief="charged(self)"/><LAND/>'
                       '</Sequence></BehaviorTree></root>')
    crash(fly_until(spec(mission, tmp_path / "run"), active("GO_TO_POINT", 1.0)))
    session, outcome = resume(tmp_path / "run")
    assert outcome.exit_status == 0, (outcome.status, [e.detail for e in session.engine.log.events("tree_error")])


LEGS = """<root BTCPP_format="4" main_tree_to_execute="Legs"><BehaviorTree ID="Legs"><Sequence>
  <TAKE_OFF ALTITUDE="3"/>
  <GO_TO_POINT COORDINATES="0, -12, 3"/>
  <GO_TO_POINT COORDINATES="8, -12, 3"/>
  <GO_TO_POINT COORDINATES="0, 0, 3"/>
  <LAND/>
</Sequence></BehaviorTree></root>"""


def test_a_tree_changed_in_flight_resumes_as_it_was_changed(tmp_path):
    """A waypoint inserted (and the next one modified) while the tree flies, then a crash on the leg after the
    inserted one: the resumed run flies the changed tree from there; the inserted waypoint is flown once, the
    modified leg with its new value, and the .btlog goes on in the changed tree's file."""
    mission = tmp_path / "legs.xml"
    mission.write_text(LEGS)
    folder = tmp_path / "run"
    run = fly_until(spec(mission, folder), active("GO_TO_POINT", 1.0))
    for command, argument in (("insert", "after 2 'GO_TO_POINT COORDINATES=\"4, -6, 3\" name=\"extra look\"'"),
                              ("modify", "4 COORDINATES=\"8, -8, 3\"")):
        ticket = run.engine.supervisor.submit(command, argument, origin="test")
        run.engine.step(run.engine.period)
        assert ticket.result is not None and ticket.result.ok, ticket.result
    assert run.engine.run_until(lambda: goals_after(3, "GO_TO_POINT")(run) and active("GO_TO_POINT", 1.0)(run),
                                LIMIT)
    crash(run)
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    flown = [tuple(arguments["COORDINATES"]) for behavior, arguments in achieved(folder)
             if behavior == "GO_TO_POINT"]
    assert flown == [(0, -12, 3), (4, -6, 3), (8, -8, 3), (0, 0, 3)]
    end = final_state(folder)
    assert end["landed_state"] == "on_ground" and math.dist(end["position"][:2], (0, 0)) < 1.0
    assert (folder / "mission.change-2.btlog").is_file()  # one file per change: the resumed run went on in the last
    assert not (folder / "mission.change-3.btlog").exists()
