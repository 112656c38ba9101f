"""The event log writer on an in-process engine, reading a log back, and the summary ``aeroexec report`` draws."""

import json

import aeroexec.engine.api as api
import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.engine.supervision.output import choose_output_folder
from aeroexec.flight.flight_log import FlightLogWriter, plain, read_flight_log
from aeroexec.flight.output import prepare_output
from aeroexec.flight.summary import final_beliefs, summarize
from hypothesis import given
from hypothesis import strategies as st


def test_the_writer_logs_events_belief_changes_and_samples_then_closes(tmp_path):
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    writer = FlightLogWriter(engine, tmp_path / "log" / "events.jsonl", sample_period=1.0, meta={"mission": "t"})

    def mission():
        api.execute_behavior("TAKE_OFF")
        api.execute_behavior("GO_TO_POINT", coordinates=[3, 0, 2])
        api.execute_behavior("GO_TO_POINT", coordinates=[99, 0, 2])  # outside the world: refused
        api.execute_behavior("LAND")

    try:
        engine.run(mission, max_time=120)
    finally:
        engine.stop()
        writer.close()
    writer.close()  # twice is harmless
    lines = (tmp_path / "log" / "events.jsonl").read_text().splitlines()
    records = [json.loads(line) for line in lines]
    assert records == read_flight_log(tmp_path / "log" / "events.jsonl")
    assert records[0]["mission"] == "t" and records[-1]["kind"] == "log_closed"
    samples = [r for r in records if r["kind"] == "state"]
    assert all(round(b["time"] - a["time"], 3) == 1.0 for a, b in zip(samples, samples[1:-1], strict=False))
    summary = summarize(records)
    assert summary.outcome == "completed with refused requests" and 5.5 < summary.distance < 12
    assert [(s.behavior, s.outcome) for s in summary.behaviors if s.source == "mission"] == [
        ("TAKE_OFF", "GOAL_ACHIEVED"), ("GO_TO_POINT", "GOAL_ACHIEVED"), ("LAND", "GOAL_ACHIEVED")]
    refused = [f for f in summary.failures if f.behavior == "GO_TO_POINT"]
    assert refused and refused[0].kind in ("failed_preconditions", "rejected") and "GO_TO_POINT" in refused[0].reason
    go = next(s for s in summary.behaviors if s.behavior == "GO_TO_POINT")
    assert go.arguments["COORDINATES"] == [3, 0, 2]
    assert go.end_position is not None and abs(go.end_position[0] - 3) < 0.6
    assert summary.battery_used is not None and summary.battery_used > 0
    assert "flight_state(self, landed)" in final_beliefs(records)
    assert engine.log.events(kind="GOAL_ACHIEVED")  # the engine is untouched by its log


def test_a_torn_last_line_is_left_out_and_a_torn_middle_line_is_an_error(tmp_path):
    log = tmp_path / "events.jsonl"
    log.write_text('{"time": 0, "kind": "log_started"}\n{"time": 1, "kind": "sta')
    assert read_flight_log(log) == [{"time": 0, "kind": "log_started"}]
    log.write_text('{"time": 0, "kind": "log_started"}\n{"time": 1, "ki\n{"time": 2, "kind": "x"}\n')
    with pytest.raises(ValueError, match=":2:"):
        read_flight_log(log)


def test_summary_of_a_log_cut_short_keeps_running_behaviors_open():
    records = [{"time": 0.0, "kind": "log_started"},
               {"time": 0.0, "kind": "state", "position": [0, 0, 0], "battery": 100.0},
               {"time": 0.5, "kind": "activated", "behavior": "GO_TO_POINT", "arguments": {}},
               {"time": 0.5, "kind": "belief_added", "belief": "flight_state(self, moving)", "reason": "add"},
               {"time": 1.0, "kind": "state", "position": [3, 4, 0], "battery": 99.0},
               {"time": 1.5, "kind": "TIME_OUT", "behavior": "WAIT", "reason": "never activated"}]
    summary = summarize(records)
    assert summary.outcome == "incomplete" and summary.distance == 5.0 and summary.battery_used == 1.0
    assert summary.behaviors[0].outcome == "RUNNING" and summary.behaviors[0].end == 1.5
    assert summary.behaviors[0].start_position == (1.5, 2.0, 0.0)  # interpolated between the samples
    assert [b.belief for b in summary.beliefs] == ["flight_state(self, moving)"] and not summary.beliefs[0].removed
    assert [f.kind for f in summary.failures] == ["TIME_OUT"]


def test_plain_values_are_json(tmp_path):
    assert plain({"a": (1, float("nan")), "p": tmp_path}) == {"a": [1, None], "p": str(tmp_path)}


def test_the_output_folder_is_chosen_in_one_place(tmp_path):
    assert choose_output_folder(tmp_path / "x") == tmp_path / "x"
    first = prepare_output(base=tmp_path)
    second = prepare_output(base=tmp_path)
    assert first != second and first.is_dir() and second.is_dir() and first.parent == tmp_path


def test_runs_started_in_the_same_second_never_share_a_folder(tmp_path):
    import threading

    chosen, start = [], threading.Barrier(8)

    def choose():
        start.wait()
        chosen.append(choose_output_folder(base=tmp_path))

    threads = [threading.Thread(target=choose) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(set(chosen)) == 8 and all(folder.is_dir() for folder in chosen)


@pytest.mark.parametrize(("text", "time"), [("position(self, (1.5, -2.25, 3.0))", 12.3456),
                                            ('message(d1, "h\u00e9llo \\"x\\"\\n")', 3.0),
                                            ("object('scout-4', drone)", 1e17), ("charge(battery, 99)", 0.0004)])
def test_a_belief_line_is_the_json_of_its_record(text, time):
    """The belief line is made by hand (the log's most frequent line): it reads back as its record would."""
    from aeroexec.beliefs import BeliefChange, format_term, parse_term
    from aeroexec.flight.flight_log import belief_line

    change = BeliefChange("removed", parse_term(text), "replaced", time)
    record = {"time": round(time, 3), "kind": "belief_removed", "belief": format_term(change.belief),
              "reason": "replaced"}
    assert belief_line(change) == json.dumps(record, separators=(",", ":"))
    with pytest.raises(ValueError):
        belief_line(BeliefChange("added", parse_term(text), "add", float("nan")))


@pytest.mark.parametrize("text", ["position(self, (1.5, -2.25, 3.0))", "speed(self, 0.1)", "orientation(self, -179)",
                                  "charge(battery, 99)", "flight_state(self, 'taking off')", "p(1e+17, -0.0)",
                                  "q((1.0,), (1, 2.5), [1.0, 2.0], f(x))", "r(1.0, true, ?X)",
                                  'message(d1, "h\u00e9llo \\"x\\"")', "wind(self, (1e-07, 2.5e+300))"])
def test_the_event_log_writes_a_belief_as_its_text_and_a_replaced_one_as_it_was_added(text):
    """The log's fast text of a belief is the term's text; a value replaced is written removed with the text it
    was added with (issue 45: one formatting per value, not two)."""
    from aeroexec.beliefs import BeliefChange, format_term, parse_term
    from aeroexec.flight.flight_log import belief_line, flat_text

    term = parse_term(text)
    assert flat_text(term) == format_term(term)
    texts: dict = {}
    added = json.loads(belief_line(BeliefChange("added", term, "add", 1.0), texts))
    removed = json.loads(belief_line(BeliefChange("removed", type(term)(term.name, term.args), "replaced", 2.0), texts))
    assert added["belief"] == removed["belief"] == format_term(term)
    assert (removed["kind"], removed["reason"], removed["time"]) == ("belief_removed", "replaced", 2.0)


_FIRSTS = st.sampled_from(["self", "d1", "scout-4", "Self", "taking off", "", "h\u00e9llo", 'a"b', "_x"])
_FLOATS = st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from([0.0, -0.0, 1e17, 1e-07, 2.5e300])
_SECONDS = (_FLOATS | st.integers(-10**20, 10**20) | st.booleans() | _FIRSTS
            | st.tuples(_FLOATS, _FLOATS, _FLOATS) | st.tuples(_FLOATS, st.integers(), _FLOATS)
            | st.tuples(_FLOATS, _FLOATS))


@given(st.sampled_from(["position", "speed", "orientation", "flight_state"]), _FIRSTS, _SECONDS)
def test_the_fast_text_of_a_belief_of_one_thing_is_its_term_text(name, first, second):
    """A belief of two arguments, the first an atom (what telemetry writes: a position, a speed, a state): its text
    made at once, the atoms known (the second call), is format_term's, for every float (-0.0, NaN, 1e17), int, bool,
    atom that must be quoted and tuple."""
    from aeroexec.beliefs import Struct, format_term
    from aeroexec.flight.flight_log import flat_text

    term = Struct(name, (first, second))
    assert flat_text(term) == format_term(term)
    assert flat_text(term) == format_term(term)  # its atoms known now: the fast path


def test_a_state_line_is_of_the_telemetry_it_is_asked_for_when_another_takes_a_freed_ones_place():
    """Two drones sampled at the same time (a fleet's journals and event logs, one period): the second drone's
    telemetry, made where the first's was freed, gets its own line, not the first drone's position."""
    from aeroexec.drones.interface import Telemetry
    from aeroexec.flight.flight_log import state_line

    first = Telemetry(time=5.0, position=(1.0, 2.0, 3.0))
    assert json.loads(state_line(5.0, first))["position"] == [1.0, 2.0, 3.0]
    address = id(first)
    del first
    made = []
    for _ in range(100):  # the allocator hands the freed place out again at once, as in a fleet's period
        second = Telemetry(time=5.0, position=(7.0, 8.0, 9.0))
        if id(second) == address:
            break
        made.append(second)
    assert json.loads(state_line(5.0, second))["position"] == [7.0, 8.0, 9.0]
