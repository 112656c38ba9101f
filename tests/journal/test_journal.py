"""The flight journal a run writes: what it holds and how it agrees with events.jsonl, what ``aeroexec journal``
answers, the report and the console's replay reading it, and the runs it refuses to resume."""

from __future__ import annotations

import json
import sqlite3
import time

import pytest
from aeroexec.cli.main import main
from aeroexec.flight.flight_log import read_flight_log
from aeroexec.flight.journal import Journal, JournalError, read_records
from aeroexec.flight.journal.resume_point import resume_point
from aeroexec.flight.journal.writer import MOTION
from aeroexec.flight.replay import replay_of
from aeroexec.flight.summary import summarize
from journeys import MISSIONS, active, crash, fly, fly_until, goals_after, resume, spec


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    """figure10.py crashed after its take-off, then resumed: a run in two parts."""
    folder = tmp_path_factory.mktemp("run")
    crash(fly_until(spec(MISSIONS / "figure10.py", folder), goals_after(1)))
    _, outcome = resume(folder)
    assert outcome.exit_status == 0
    return folder


def _motion(record: dict) -> bool:
    belief = record.get("belief", "")
    return any(belief.startswith(f"{name}(self,") for name in MOTION)


def _parts(records: list[dict]) -> list[list[dict]]:
    """A log's records, part by part (a ``log_started`` or ``log_resumed`` line starts a part)."""
    parts: list[list[dict]] = []
    for record in records:
        if record["kind"] in ("log_started", "log_resumed"):
            parts.append([])
        parts[-1].append(record)
    return parts


def _events(records: list[dict]) -> list[dict]:
    return [r for r in records if not r["kind"].startswith(("belief_", "log_")) and r["kind"] != "state"]


def _beliefs(records: list[dict]) -> list[tuple]:
    return [(r["time"], r["kind"], r["belief"], r["reason"]) for r in records
            if r["kind"].startswith("belief_") and not _motion(r)]


def test_the_journal_holds_what_events_jsonl_holds(flown):
    """Part by part: the resumed part whole; the killed part up to its last tick (what the journal had not been
    handed yet is lost with the process, as the issue allows; events.jsonl writes every record at once)."""
    (killed, resumed), (killed_again, resumed_again) = _parts(read_flight_log(flown / "events.jsonl")), \
        _parts(read_records(flown / "journal.sqlite"))
    assert _events(resumed_again) == _events(resumed)
    assert _beliefs(resumed_again) == _beliefs(resumed)
    sampled = {r["time"] for r in resumed if r["kind"] == "state"}
    kept = {r["time"] for r in resumed_again if r["kind"] == "state"}  # once a second, and when behaviors end
    assert {t for t in sampled if abs(t - round(t)) < 1e-6} <= kept and len(kept & sampled) >= len(sampled) // 2
    kept, logged = _events(killed_again), _events(killed)
    assert kept == logged[:len(kept)] and logged[len(kept) - 1]["time"] >= logged[-1]["time"] - 0.05
    assert _beliefs(killed_again) == _beliefs(killed)[:len(_beliefs(killed_again))]
    whole, again = summarize(read_flight_log(flown / "events.jsonl")), summarize(read_records(flown))
    assert (again.outcome, again.duration) == (whole.outcome, whole.duration)


def test_the_journal_tables(flown):
    with Journal(flown) as journal:
        parts = journal.segments()
        assert [(p.segment, p.status) for p in parts] == [(1, None), (2, "completed")]
        assert parts[1].started_at > 0  # the resumed run's clock goes on from the interrupted one's
        take_off = journal.behavior("take_off")
        assert [(r["source"], r["outcome"]) for r in take_off] == [("mission", "GOAL_ACHIEVED")]
        calls = journal.rows("SELECT number, function, location FROM calls WHERE superseded = 0 ORDER BY number")
        assert [(c["number"], c["function"]) for c in calls] == [
            (1, "execute_behavior"), (2, "activate_behavior"), (4, "execute_behavior"), (5, "execute_behavior"),
            (6, "inhibit_behavior"), (7, "execute_behavior")]
        assert calls[0]["location"] == "figure10.py:11"
        looks = journal.rows("SELECT first, count, calls FROM looks WHERE superseded = 0")
        assert [(r["first"], r["count"], json.loads(r["calls"])[0][0]) for r in looks] == [(3, 1, "consult_belief")]
        assert journal.rows("SELECT count(*) FROM node_transitions")[0][0] == 0  # a Python mission
        assert not journal.rows("SELECT * FROM beliefs WHERE belief LIKE 'position(self,%'")  # in telemetry
    with pytest.raises(JournalError, match="completed"):
        resume_point(flown)


def test_aeroexec_journal_answers_questions(flown, capsys):
    assert main(["journal", str(flown)]) == 0
    out = capsys.readouterr().out
    assert "part 1:" in out and "did not end" in out and "part 2:" in out and "ended completed" in out
    assert "steps done: 4" in out and "nothing is left to do" in out
    assert main(["journal", str(flown), "--behavior", "GO_TO_POINT", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(r["outcome"], r["arguments"]["COORDINATES"]) for r in rows][0] == ("GOAL_ACHIEVED", [2, 5, 1.3])
    assert main(["journal", str(flown), "--belief", "flight_state(self, ?S)"]) == 0
    out = capsys.readouterr().out
    assert "+       flight_state(self, hovering)" in out and "flight_state(self, landed)" in out
    assert main(["journal", str(flown), "--done"]) == 0
    assert [line.split()[2] for line in capsys.readouterr().out.splitlines()[1:]] == \
        ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
    assert main(["journal", str(flown), "--sql", "SELECT count(*) AS n FROM segments"]) == 0
    assert capsys.readouterr().out.split() == ["n", "2"]


def test_aeroexec_journal_refuses_what_is_no_journal(tmp_path, capsys):
    (tmp_path / "journal.sqlite").write_text("not a database at all, but long enough to look at\n" * 20)
    assert main(["journal", str(tmp_path)]) == 1
    assert "not a flight journal" in capsys.readouterr().err
    assert main(["journal", str(tmp_path / "nowhere")]) == 1
    assert "no flight journal here" in capsys.readouterr().err


def test_a_query_cannot_change_the_journal(flown, capsys):
    assert main(["journal", str(flown), "--sql", "DELETE FROM events"]) == 1
    assert "readonly" in capsys.readouterr().err
    with Journal(flown) as journal:
        assert journal.rows("SELECT count(*) FROM events")[0][0] > 0


def test_the_report_and_the_replay_read_a_journal(flown, tmp_path):
    replay = replay_of(flown / "journal.sqlite")
    assert replay["mission"] == "figure10.py"
    records = replay["drones"]["drone"]
    assert any(r["kind"] == "GOAL_ACHIEVED" and r["behavior"] == "LAND" for r in records)
    assert not any(r["kind"].startswith("log_") for r in records)
    assert main(["report", str(flown / "journal.sqlite"), "--output", str(tmp_path / "report")]) == 0
    assert (tmp_path / "report" / "report.html").is_file()


def test_the_journal_is_read_while_the_run_flies_and_a_flying_run_is_not_resumed(tmp_path):
    folder = tmp_path / "run"
    run = fly_until(spec(MISSIONS / "figure10.py", folder), active("GO_TO_POINT", 1.0))
    try:
        run.journal.flush()
        with Journal(folder) as journal:
            assert [r["outcome"] for r in journal.behavior("TAKE_OFF")] == ["GOAL_ACHIEVED"]
            assert [r["outcome"] for r in journal.behavior("GO_TO_POINT")] == [None]
        with pytest.raises(JournalError, match="still flying"):
            resume_point(folder)
    finally:
        crash(run)


def test_a_mission_that_failed_by_itself_is_not_resumed(tmp_path):
    mission = tmp_path / "fails.py"
    mission.write_text("import aeroexec.engine.api as api\n\ndef mission():\n    api.execute_behavior('TAKE_OFF')\n"
                       "    raise RuntimeError('no target found')\n")
    _, outcome = fly(spec(mission, tmp_path / "run"))
    assert outcome.exit_status == 1
    with pytest.raises(JournalError, match="ended failed by itself"):
        resume_point(tmp_path / "run")


def test_a_journal_that_cannot_be_written_stops_and_the_flight_goes_on(tmp_path, monkeypatch):
    from aeroexec.flight.journal import store

    def full(self, rows):
        raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(store.JournalStore, "_write", full)
    _, outcome = fly(spec(MISSIONS / "figure10.py", tmp_path / "run"))
    assert outcome.status.word == "completed" and outcome.exit_status == 6
    assert outcome.log_incomplete == "the journal: database or disk is full"


def test_the_journal_is_checkpointed_while_the_run_flies_and_whole_after_a_kill(tmp_path, monkeypatch):
    """The loop only appends to the WAL; the journal's thread copies it into the database as the run goes (here
    every 5 commits), and a journal left by a killed process (its WAL not checkpointed) reads whole."""
    from aeroexec.flight.journal import store

    monkeypatch.setattr(store, "CHECKPOINT_COMMITS", 5)
    monkeypatch.setattr(store, "CHECKPOINT_PERIOD", 60.0)
    folder = tmp_path / "run"
    run = fly_until(spec(MISSIONS / "figure10.py", folder), goals_after(2))
    try:
        database = folder / "journal.sqlite"
        for _ in range(200):  # the checkpoint is the thread's: a moment (10 s at most on a loaded machine)
            if database.stat().st_size > 8 * 4096:
                break
            run.engine.step(run.engine.period)
            run.journal.flush()
            time.sleep(0.05)
        assert database.stat().st_size > 8 * 4096  # the events so far are in the database itself
        assert (folder / "journal.sqlite-wal").is_file()
    finally:
        crash(run)
    with Journal(folder) as journal:
        assert [r["outcome"] for r in journal.behavior("TAKE_OFF")] == ["GOAL_ACHIEVED"]
        assert journal.rows("SELECT count(*) FROM events")[0][0] > 20


def test_the_journal_writes_null_where_nothing_is_known_as_it_did_binding_none(tmp_path):
    """A record that does not expire and a call not yet returned are written by statements that say NULL (binding
    None costs an adapter look-up): the rows hold what binding None wrote, NULL and 0, and a belief that lasts a
    while still has the time it expires at."""
    from aeroexec.drones.sim import SimulatedDrone, default_world
    from aeroexec.engine.engine import Engine
    from aeroexec.flight.journal.writer import JournalWriter

    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    engine.memory.declare("seen", 1, persistence=2.5)
    engine.memory.declare("noted", 1)
    writer = JournalWriter(engine, tmp_path)
    try:
        engine.step(0.1)
        engine.memory.add("seen(box)")
        engine.memory.add("noted(box)")
        writer.call_requested(1, "consult_belief", "['seen(box)']", "m.py:3", engine.now())
        writer.call_requested(2, "execute_behavior", "['LAND']", "m.py:4", engine.now())
        writer.call_returned(2, "execute_behavior", "['LAND']", "m.py:4", engine.now(), '"GOAL_ACHIEVED"', None)
        engine.step(0.1)
    finally:
        writer.close()
        engine.stop()
    db = sqlite3.connect(tmp_path / "journal.sqlite")
    added = dict(db.execute("SELECT json_extract(record, '$.belief'), expires_at FROM events "
                            "WHERE kind = 'belief_added' AND json_extract(record, '$.belief') LIKE '%(box)'"))
    time_added = db.execute("SELECT time FROM events WHERE record LIKE '%seen(box)%'").fetchone()[0]
    assert added == {"seen(box)": round(time_added + 2.5, 3), "noted(box)": None}
    assert db.execute("SELECT count(*) FROM events WHERE expires_at IS NOT NULL AND kind != 'belief_added'"
                      ).fetchone()[0] == 0
    calls = db.execute("SELECT number, returned_at, result, error, after_stop, superseded, typeof(after_stop) "
                       "FROM calls ORDER BY number").fetchall()
    assert calls[0] == (1, None, None, None, 0, 0, "integer")
    assert calls[1][1:] == (calls[1][1], '"GOAL_ACHIEVED"', None, 0, 0, "integer") and calls[1][1] is not None
