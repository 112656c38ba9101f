"""The simulation campaign (``aeroexec campaign``): a fixed-seed campaign of whole flights keeps every invariant;
each invariant says its name when it fails; a failing case is replayed from its seed by the command it prints and
shrinks; and what the campaign found, fixed."""

from __future__ import annotations

import json
import math
import os
from dataclasses import replace
from pathlib import Path

from aeroexec.cli.main import main
from aeroexec.flight.session import FlightSession
from aeroexec.flight.signals import Interrupted
from aeroexec.flight.spec import FlightSpec
from aeroexec.rehearsal.simulation import (
    Action,
    Fault,
    check,
    draw,
    invariants,
    replay_command,
    run_campaign,
    shrink,
)
from aeroexec.rehearsal.simulation.flights import fly_case
from aeroexec.rehearsal.simulation.missions import Mission

ROOT = Path(__file__).parents[2]
FIGURE10 = ROOT / "missions" / "figure10.xml"
FLIGHTS = 300  # the suite's campaign: seeds 0 to 299


def test_a_fixed_seed_campaign_of_300_flights_keeps_every_invariant():
    results = run_campaign(range(FLIGHTS), workers=os.cpu_count() or 2)
    assert len(results) == FLIGHTS
    failed = [r.report() for r in results if r.violations]
    assert not failed, "\n\n".join(failed)
    ended = {r.ended for r in results}
    assert {"completed", "failed", "aborted"} <= ended  # the campaign reaches more than one way to end
    assert sum(r.parts == 2 for r in results) >= 10  # killed and resumed runs among them
    assert sum("a real aeroexec run process" in r.description for r in results) >= 3
    assert sum("aeroexec fleet" in r.description for r in results) >= 3


def test_the_same_seed_draws_the_same_case_and_others_differ():
    assert draw(41) == draw(41)
    assert len({draw(seed).mission.text for seed in range(20)}) == 20
    kinds = {draw(seed).mission.kind for seed in range(60)}
    assert kinds == {"tree", "python", "plan"}


def _case_with(seed: int, **changes):  # noqa: ANN003
    return replace(draw(seed), **changes)


def test_a_broken_invariant_is_named_with_the_command_that_replays_it(tmp_path, monkeypatch):
    monkeypatch.setattr(invariants, "STEP_BOUND", 0.0)  # every step is now too long
    case = _case_with(3, actions=(), faults=(), rules=None, safety_rules=None)
    found = check(fly_case(case, tmp_path))
    assert [v.invariant for v in found] == ["step_bound"]
    assert str(found[0]).startswith("step_bound: an engine step of part 1 at t=")
    assert replay_command(3, ("process_signal",)) == "aeroexec campaign --seed 3 --with process_signal"


def test_an_event_log_cut_mid_line_and_a_drone_left_armed_are_violations(tmp_path):
    case = _case_with(3, actions=(), faults=(), rules=None, safety_rules=None)
    flown = fly_case(case, tmp_path)
    log = flown.folder / "events.jsonl"
    log.write_bytes(log.read_bytes() + b'{"time": 1, "kind": "torn')
    flown.parts[-1].armed = True
    names = {v.invariant for v in check(flown)}
    assert {"event_log_whole", "landed_and_disarmed"} <= names


def test_a_failing_case_shrinks_to_what_still_fails_it(monkeypatch):
    monkeypatch.setattr(invariants, "STEP_BOUND", 0.0)
    case = _case_with(5, actions=(Action(1.0, "status"), Action(2.0, "pause"), Action(3.0, "resume")),
                      faults=(Fault("link_drop", 2.0, 1.0),))
    smaller = shrink(case, "step_bound")
    assert smaller.actions == () and smaller.faults == ()
    assert "t=2 ctl pause" in smaller.describe() and "shrunk" in smaller.describe()


def test_one_seed_is_replayed_by_one_command_with_its_files_kept(tmp_path, capsys):
    assert main(["campaign", "--seed", "7", "--output", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("seed 7: a ") and "every invariant held" in out
    assert (tmp_path / "seed-7" / "run" / "events.jsonl").is_file()


def test_sigterm_while_the_flight_ends_lands_the_drone(tmp_path):
    """Found by the campaign (seed 26): one SIGTERM while the end of the flight was landing the drone left it in the
    air, armed, as a second one should (the run 'failed: the operator interrupted the end of the flight')."""
    mission = tmp_path / "no_landing.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>'
                       '<TAKE_OFF ALTITUDE="3"/><GO_TO_POINT COORDINATES="2, 1, 3"/></Sequence></BehaviorTree></root>')
    session = FlightSession(FlightSpec(mission=mission, output=str(tmp_path / "run"), register=False),
                            notify=lambda text: None)
    session.open()
    signalled = []

    def signal_while_landing() -> None:  # as the handler raises it in the loop's thread
        if not signalled and session.engine.log.events("landing"):
            signalled.append(session.engine.now())
            raise Interrupted("SIGTERM")

    session.engine.tick_callbacks.append(signal_while_landing)
    outcome = session.fly()
    assert signalled
    telemetry = session.robot.telemetry()
    assert not telemetry.armed and telemetry.position[2] < 0.3
    assert outcome.status.word == "aborted" and not outcome.faults


def test_a_second_signal_while_the_flight_ends_leaves_the_drone_as_it_is(tmp_path):
    mission = tmp_path / "no_landing.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>'
                       '<TAKE_OFF ALTITUDE="3"/><GO_TO_POINT COORDINATES="2, 1, 3"/></Sequence></BehaviorTree></root>')
    session = FlightSession(FlightSpec(mission=mission, output=str(tmp_path / "run"), register=False),
                            notify=lambda text: None)
    session.open()
    signalled = []

    def twice_while_landing() -> None:
        if len(signalled) < 2 and session.engine.log.events("landing"):
            signalled.append(session.engine.now())
            raise Interrupted("SIGTERM")

    session.engine.tick_callbacks.append(twice_while_landing)
    outcome = session.fly()
    assert len(signalled) == 2
    assert session.robot.telemetry().position[2] > 1.0  # left where it was
    assert outcome.status.word == "failed" and "the drone was left as it was" in outcome.faults[0]


def test_a_run_killed_while_landing_after_its_mission_failed_is_not_flown_again(tmp_path):
    """Found by the campaign (seed 177 with crash_after_end): kill -9 while the end of the flight landed the drone,
    after the tree had failed, then --resume flew the whole tree again (each goal reached twice over the run)."""
    text = ('<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
            '<TAKE_OFF ALTITUDE="3"/><GO_TO_POINT COORDINATES="2, 1, 3"/><AlwaysFailure/><LAND/>'
            '</Sequence></BehaviorTree></root>')
    mission = Mission("tree", text, ".xml", ((2.0, 1.0, 3.0),), False, 4)
    case = _case_with(5, mission=mission, actions=(), faults=(Fault("crash", 7.0),), rules=None, safety_rules=None)
    flown = fly_case(case, tmp_path)
    assert [v.invariant for v in check(flown)] == []
    first, resumed = flown.parts
    assert first.crashed
    assert resumed.refused and "had ended failed by itself" in resumed.refused
    records = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    assert [r["kind"] for r in records].count("mission_started") == 1  # the mission flew once


def test_a_pause_while_the_flight_ends_is_refused_and_the_drone_lands(tmp_path):
    """Found by the campaign (seed 3913 of the 10,000): a pause after the mission had ended stopped the end of the
    flight's return and then its LAND, and the run ended 'failed: the drone was left in the air at 5.7 m'."""
    text = ('<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
            '<TAKE_OFF ALTITUDE="3"/><GO_TO_POINT COORDINATES="2, 1, 3"/></Sequence></BehaviorTree></root>')
    mission = Mission("tree", text, ".xml", ((2.0, 1.0, 3.0),), False, 2)
    case = _case_with(5, mission=mission, actions=(Action(7.0, "pause"),), faults=(), rules=None, safety_rules=None)
    flown = fly_case(case, tmp_path)
    assert [v.invariant for v in check(flown)] == []
    records = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    kinds = [r["kind"] for r in records]
    assert kinds.index("mission_completed") < kinds.index("drone_landed")
    pause = next(r for r in records if r["kind"] == "operator_command")
    assert pause["time"] > records[kinds.index("mission_completed")]["time"]
    assert not pause["data"]["ok"] and "the flight is ending" in pause["detail"]
    ended = records[kinds.index("run_ended")]
    assert ended["detail"] == "completed"


def test_a_hold_crossed_at_speed_lands_where_the_rule_holds_not_past_it(tmp_path):
    """Found by the campaign (seed 6121 of the 10,000): a plan crossed a hold fence at 5 m/s; the drone hovered where
    it stopped, 4 m past the boundary, and the end of the flight landed it there, outside the fence."""
    text = ('<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
            '<TAKE_OFF ALTITUDE="7"/><SetBlackboard output_key="far" value="8, -17.5, 7"/>'  # unseen before flight
            '<GO_TO_POINT COORDINATES="{far}"/><LAND/></Sequence></BehaviorTree></root>')
    fence = ("- rule: fence\n  never: position(self, ?p), distance(?p, (0, 0, 0), ?d), ?d > 12\n"
             "  contingency: hold\n")
    mission = Mission("tree", text, ".xml", ((8.0, -17.5, 7.0),), False, 3)
    case = _case_with(5, mission=mission, actions=(), faults=(), rules=None, safety_rules=fence)
    flown = fly_case(case, tmp_path)
    assert flown.parts[0].refused is None
    assert [v.invariant for v in check(flown)] == []
    records = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    landed = next(r for r in records if r["kind"] == "drone_landed")
    assert math.dist(landed["data"]["position"][:2], (0.0, 0.0)) <= 12.5  # on the fence, not metres outside it
    assert any("flown back there before it lands" in r.get("detail", "") for r in records)


def _records_of(folder: Path, kind: str) -> list[dict]:
    return [r for r in map(json.loads, (folder / "events.jsonl").read_text().splitlines()) if r.get("kind") == kind]


def test_a_real_process_gets_its_signal_at_the_faults_engine_time(tmp_path):
    """Found by the campaign (seed 70243, a real ``aeroexec run`` process given SIGHUP at t=1.92): the signal was
    sent from outside once the event log had reached the fault's time, while the run flew on as fast as it could,
    so it landed seconds of engine time later, by how soon the sender was scheduled (the abort said "landing" in
    one run, "the drone is on the ground" in another; under load a run could end before its signal came). The
    process now sends it itself at the first period at or after the fault's time: the seed decides the outcome."""
    from aeroexec.rehearsal.simulation.processes import fly_process

    case = draw(70243)
    assert case.subprocess and [(f.kind, f.time) for f in case.faults] == [("sighup", 1.92)]
    flown = fly_process(case, tmp_path)
    interrupts = _records_of(tmp_path / "run", "operator_interrupt")
    assert [(r["time"], r["detail"]) for r in interrupts] == [(1.95, "SIGHUP")]  # the period after 1.9 < 1.92
    assert flown.parts[-1].outcome.status.word == "aborted"
    assert not check(flown)


def test_a_real_process_killed_at_the_faults_engine_time_is_resumed(tmp_path):
    """``kill -9`` as the process's own SIGKILL at the fault's time: its event log stops in that period, and
    ``aeroexec run --resume`` flies the rest."""
    from aeroexec.rehearsal.simulation.processes import fly_process

    case = replace(draw(70243), faults=(Fault("crash", 2.0),))
    flown = fly_process(case, tmp_path)
    assert len(flown.parts) == 2 and flown.parts[0].crashed
    first = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    resumed = next(i for i, r in enumerate(first) if r.get("kind") == "log_resumed")
    assert max(r.get("time", 0.0) for r in first[:resumed]) == 2.0
    assert not check(flown)


def test_outcomes_are_written_one_json_line_per_seed_the_same_each_run(tmp_path, capsys):
    runs = []
    for name in ("a.jsonl", "b.jsonl"):
        assert main(["campaign", "--flights", "4", "--first", "70052", "--workers", "1",
                     "--outcomes", str(tmp_path / name)]) == 0
        runs.append((tmp_path / name).read_text())
    lines = [json.loads(line) for line in runs[0].splitlines()]
    assert [line["seed"] for line in lines] == [70052, 70053, 70054, 70055]
    assert set(lines[0]) == {"seed", "ended", "why", "steps", "parts", "violated"}
    assert runs[0] == runs[1]  # no scratch folders, run identities or costs in them
    assert main(["campaign", "--flights", "1", "--outcomes", str(tmp_path / "no" / "such" / "x.jsonl")]) == 2
    assert "--outcomes" in capsys.readouterr().err


def test_a_campaign_flown_in_this_process_leaves_the_engines_warnings_on(caplog):
    # one worker flies the cases in the calling process: what the runs log below an error stays in the runs, but
    # the program's own warnings afterwards are still logged (a campaign left the engine's loggers at ERROR)
    import logging

    assert main(["campaign", "--flights", "1", "--first", "70052", "--workers", "1"]) == 0
    logging.getLogger("aeroexec.dialects.aerostack2.sim_world").warning("heard after the campaign")
    assert "heard after the campaign" in caplog.text
