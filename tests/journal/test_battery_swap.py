"""Battery swaps as a first-class stop: the low-battery landing (or ``ctl suspend``) ends the run ``suspended`` with
the journal saying where; resumed with a full battery, the drone takes off again, flies back to where the survey
stopped, and finishes it without flying its done legs again."""

from __future__ import annotations

import math

import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.flight.journal import Journal, JournalError
from aeroexec.flight.journal.resume_point import resume_point
from aeroexec.flight.run_status import SUSPENDED
from journeys import MISSIONS, achieved, active, final_state, fly, fly_until, photos, resume, same_goals, spec

SURVEY = MISSIONS / "survey.plan"


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    folder = tmp_path_factory.mktemp("whole")
    _, outcome = fly(spec(SURVEY, folder))
    assert outcome.exit_status == 0
    return folder


def test_a_low_battery_landing_mid_survey_is_resumed_after_the_swap(whole, tmp_path):
    folder = tmp_path / "run"
    weak = SimulatedDrone(default_world(), config=SimConfig(initial_battery_percent=40.0, battery_hover_minutes=3.0))
    first, outcome = fly(spec(SURVEY, folder), robot=weak)
    assert outcome.exit_status == 5 and outcome.status.word == SUSPENDED
    assert "LAND on low battery" in outcome.status.reasons[0]
    done_first = achieved(folder)
    legs_first = [args["COORDINATES"] for behavior, args in done_first if behavior == "GO_TO_POINT"]
    assert 2 <= len(legs_first) < 10  # it stopped mid-survey
    point = resume_point(folder)
    assert point.stop["kind"] == "reactive" and "LAND on low battery" in point.stop["reason"]
    assert point.was_flying and point.place[2] > 10  # the survey's altitude, where it stopped
    assert point.suspended

    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    events = session.engine.log.events()
    rejoin = [e for e in events if e.kind == "activated" and e.data.get("source") == "resume"]
    assert [e.behavior for e in rejoin] == ["TAKE_OFF", "GO_TO_POINT"]  # off the ground, back to the stop
    assert math.dist(rejoin[1].data["arguments"]["COORDINATES"], point.place) < 0.01
    legs_again = [e.data["arguments"]["COORDINATES"] for e in events
                  if e.kind == "activated" and e.behavior == "GO_TO_POINT" and e.data.get("source") == "mission"]
    assert not set(map(tuple, legs_first)) & set(map(tuple, legs_again))  # no done leg flown again
    difference = same_goals(achieved(folder), achieved(whole))
    assert difference is None, difference
    assert photos(folder) == photos(whole)
    assert session.engine.drone.telemetry().battery_percent > 80  # the swapped battery
    end = final_state(folder)
    assert end["landed_state"] == "on_ground" and math.dist(end["position"], final_state(whole)["position"]) < 1.0


def test_ctl_suspend_ends_the_run_suspended_and_the_resume_goes_on(whole, tmp_path):
    folder = tmp_path / "run"
    run = fly_until(spec(SURVEY, folder), active("GO_TO_POINT", 2.0))
    ticket = run.engine.supervisor.submit("suspend", origin="ctl")
    outcome = run.fly() if False else _finish(run)
    assert ticket.result.ok and "suspended" in ticket.result.message
    assert outcome.exit_status == 5 and outcome.status.word == SUSPENDED
    with Journal(folder) as journal:
        segment = journal.segments()[0]
        stop = journal.progress(1, "stop")[2]
    assert segment.status == SUSPENDED and segment.exit_status == 5
    assert stop["kind"] == "mission_suspended" and stop["drone"]["landed_state"] == "in_air"
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    assert same_goals(achieved(folder), achieved(whole)) is None
    with pytest.raises(JournalError, match="completed"):
        resume_point(folder)


def _finish(run):
    """Fly a started session to its end as ``fly()`` does after its start."""
    from aeroexec.flight.ending import end_flight

    engine = run.engine
    if not engine.run_until(lambda: run.mission_done, 600):
        run.time_limit()
    return run.finish(end_flight(engine, link_grace=run.spec.link_grace))


def test_the_console_suspends_as_ctl_does(tmp_path):
    """The console's suspend button sends ``suspend`` over its socket: the run ends suspended, the journal says
    where, and the resume finishes the mission."""
    import json
    import threading

    from aeroexec.flight.session import FlightSession
    from websockets.sync.client import connect

    heard: list[str] = []
    folder = tmp_path / "run"
    session = FlightSession(spec(MISSIONS / "survey_legs.xml", folder, web=0, speed=4.0), notify=heard.append)
    outcome: list = []
    flying = threading.Thread(target=lambda: outcome.append(session.fly()), daemon=True)
    session.open()
    flying.start()
    url = next(line.split()[-1] for line in heard if "http://" in line)
    base, token = url.split("?")
    with connect(base.replace("http", "ws") + "ws?" + token, open_timeout=10) as ws:
        assert json.loads(ws.recv(timeout=10))["type"] == "hello"
        while not session.engine.coordinator.is_active("GO_TO_POINT"):
            ws.recv(timeout=10)
        ws.send(json.dumps({"id": 1, "drone": "drone", "command": "suspend", "argument": ""}))
        while (reply := json.loads(ws.recv(timeout=10)))["type"] != "result":
            pass
    assert reply["ok"], reply
    flying.join(timeout=60)
    assert outcome and outcome[0].exit_status == 5, outcome
    stop = resume_point(folder).stop
    assert stop["kind"] == "mission_suspended" and "web console" not in stop["reason"]
    _, finished = resume(folder)
    assert finished.exit_status == 0, finished.status


def test_a_resumed_run_stopped_again_resumes_again_with_what_it_held(tmp_path):
    """Suspended twice (ctl suspend), resumed twice: the beliefs and the background behaviors the first part had
    come back in the third, and the survey ends with every goal once."""
    folder = tmp_path / "run"
    mission = tmp_path / "survey.py"
    mission.write_text("import aeroexec.engine.api as api\n\ndef mission():\n"
                       "    api.execute_behavior('TAKE_OFF', altitude=3)\n"
                       "    api.add_belief('surveyed(north)')\n"
                       "    api.activate_behavior('PAY_ATTENTION_TO_VISUAL_MARKERS')\n"
                       "    for corner in [(0, -12, 3), (8, -12, 3), (8, -16, 3), (0, -16, 3)]:\n"
                       "        api.execute_behavior('GO_TO_POINT', coordinates=corner)\n"
                       "    assert api.true_belief('surveyed(north)')\n"
                       "    api.execute_behavior('LAND')\n")
    for leg in (1, 2):
        run = fly_until(spec(mission, folder) if leg == 1 else _resumed(folder), active("GO_TO_POINT", 1.0))
        run.engine.supervisor.submit("suspend", origin="ctl")
        assert _finish(run).exit_status == 5
        if leg == 2:
            assert run.engine.memory.holds("surveyed(north)")
            assert "PAY_ATTENTION_TO_VISUAL_MARKERS" in [e.behavior for e in run.engine.log.events("activated")]
    session, outcome = resume(folder)
    assert outcome.exit_status == 0, outcome.status
    assert [b for b, _ in achieved(folder)] == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "GO_TO_POINT", "GO_TO_POINT",
                                                "LAND"]


def _resumed(folder):
    from dataclasses import replace

    from aeroexec.flight.journal import resume_spec

    return replace(resume_spec(folder), register=False)
