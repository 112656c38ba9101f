"""The journal and the event log agree on every record both hold (``flight/journal/agreement.py``), however the
run ends: a SIGTERM (or Ctrl-C) that lands mid-commit waits for the engine period's end instead of losing the
commit's records; and after ``kill -9`` + ``--resume`` the event log's time goes on from its last record, never
back by more than one engine period."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

from aeroexec.flight.journal import Journal
from aeroexec.flight.journal.agreement import disagreements
from aeroexec.flight.journal.schema import NAME
from aeroexec.flight.journal.store import JournalStore
from aeroexec.flight.signals import ending_signals, interrupts_held
from journeys import MISSIONS, fly, spec

RUN_S = 120.0  # s, wall: longest a run below may take
PERIOD = 0.05  # s: the engine's period
MOTION = ("position(self", "speed(self", "orientation(self")  # the journal keeps state samples of them instead


def records(folder: Path) -> list[dict]:
    return [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]


def test_a_sigterm_during_a_journal_commit_loses_no_record(tmp_path, monkeypatch):
    """square_patrol.py SIGTERM'd while the journal commits a batch of belief changes: the run lands as for Ctrl-C
    and the journal holds every record the event log holds (a commit cut by the signal was rolled back)."""
    write = JournalStore._write
    sent = []

    def commit(store, rows):
        if not sent and sum("belief_added" in str(row[1]) for row in rows) >= 3:
            sent.append(len(rows))
            os.kill(os.getpid(), signal.SIGTERM)  # its handler runs in the middle of this commit
        write(store, rows)

    monkeypatch.setattr(JournalStore, "_write", commit)
    folder = tmp_path / "run"
    with ending_signals():
        _, outcome = fly(spec(MISSIONS / "square_patrol.py", folder))
    assert sent, "no commit of belief changes"
    assert "SIGTERM" in outcome.status.reasons[0], outcome.status.reasons
    assert disagreements(folder) == []
    logged = Counter(r["kind"] for r in records(folder) if not r.get("belief", "").startswith(MOTION))
    with Journal(folder) as journal:
        kept = Counter(r["kind"] for r in journal.rows("SELECT kind FROM events"))
    assert kept["belief_added"] == logged["belief_added"] > 0
    assert kept["operator_interrupt"] == logged["operator_interrupt"] == 1


def test_disagreements_names_what_the_journal_lacks(tmp_path):
    folder = tmp_path / "run"
    fly(spec(MISSIONS / "survey_legs.xml", folder))
    assert disagreements(folder) == []
    with sqlite3.connect(folder / NAME) as db:
        db.execute("DELETE FROM events WHERE seq = (SELECT max(seq) FROM events WHERE kind = 'GOAL_ACHIEVED')")
    counted, differs = disagreements(folder)
    assert counted.startswith("part 1 (ended completed): the event log holds 106 records (5 GOAL_ACHIEVED"), counted
    assert "the journal 105 (4 GOAL_ACHIEVED" in counted, counted
    assert "part 1 (ended completed): record 91 differs: the event log has" in differs, differs
    assert '"behavior":"LAND"' in differs.split("the journal")[0], differs


def kill_9_mid_leg(mission: Path, folder: Path) -> None:
    """``aeroexec run MISSION`` at 10x real time, killed with SIGKILL once its event log holds 4 state samples
    after the last behavior activated (a GO_TO_POINT flying its leg: only telemetry and beliefs, which the journal
    commits every few seconds, have been written since)."""
    process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--plain", "--quiet",
                                "--speed", "10", "--output", str(folder)], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE)
    log = folder / "events.jsonl"
    deadline = time.monotonic() + RUN_S
    try:
        while process.poll() is None and time.monotonic() < deadline:
            try:
                text = log.read_text()
            except OSError:
                text = ""
            last = text.rfind('"kind":"activated"')
            if text.count('"kind":"GOAL_ACHIEVED"') >= 2 and last >= 0 and '"GO_TO_POINT"' in text[last:].split(
                    "\n", 1)[0] and text[last:].count('"kind":"state"') >= 4:
                os.kill(process.pid, signal.SIGKILL)
                break
            time.sleep(0.005)
    finally:
        if process.poll() is None and time.monotonic() >= deadline:
            process.kill()
        _, err = process.communicate(timeout=RUN_S)
    assert process.returncode == -signal.SIGKILL, f"the run was not killed mid-leg: {err.decode()[-2000:]}"


def test_after_kill_9_the_resumed_runs_time_goes_on_from_the_event_log(tmp_path):
    folder = tmp_path / "run"
    kill_9_mid_leg(MISSIONS / "survey_legs.xml", folder)
    killed = records(folder)
    resumed = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", "--resume", str(folder), "--plain",
                              "--quiet"], capture_output=True, text=True, timeout=RUN_S)
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    after = records(folder)[len(killed):]
    assert after[0]["kind"] == "log_resumed"
    last_before = max(r["time"] for r in killed)
    first_after = min(r["time"] for r in after)
    assert first_after >= last_before - PERIOD, (last_before, first_after)
    times = [r["time"] for r in after]
    assert all(b >= a - PERIOD for a, b in zip(times, times[1:], strict=False))
    found = disagreements(folder)
    assert found == [], found


def test_a_signal_within_a_held_period_is_raised_at_its_end_and_a_second_at_once():
    order = []
    with ending_signals():
        try:
            with interrupts_held():
                os.kill(os.getpid(), signal.SIGTERM)
                order.append("the period went on")
        except KeyboardInterrupt as interrupt:
            order.append(interrupt.signal_name)
        try:
            with interrupts_held():
                os.kill(os.getpid(), signal.SIGTERM)
                os.kill(os.getpid(), signal.SIGHUP)  # the operator insists
                order.append("not reached")
        except KeyboardInterrupt as interrupt:
            order.append(interrupt.signal_name)
    assert order == ["the period went on", "SIGTERM", "SIGTERM"]


def test_a_patrol_sigtermed_mid_flight_keeps_every_record_in_its_journal(tmp_path):
    """``aeroexec run square_patrol.py`` SIGTERM'd once its event log holds 20 belief changes: it lands (exit 4),
    and its journal holds every record its event log holds."""
    folder = tmp_path / "run"
    process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", str(MISSIONS / "square_patrol.py"),
                                "--plain", "--quiet", "--speed", "10", "--output", str(folder)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    log = folder / "events.jsonl"
    deadline = time.monotonic() + RUN_S
    try:
        while process.poll() is None and time.monotonic() < deadline:
            try:
                seen = log.read_text().count('"kind":"belief_')
            except OSError:
                seen = 0
            if seen >= 20:
                process.send_signal(signal.SIGTERM)
                break
            time.sleep(0.005)
        _, err = process.communicate(timeout=RUN_S)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 4, err.decode()[-2000:]
    assert records(folder)[-1]["kind"] == "log_closed"
    found = disagreements(folder)
    assert found == [], found


def test_a_fleet_drones_journal_keeps_its_own_state_not_where_its_mates_are(tmp_path, capsys):
    """A mate's position is heard from the fleet (a resumed drone hears it again), not this drone's state: its
    journal, as its event log, says the mate was heard and keeps no belief change of where it is."""
    from aeroexec.cli.main import main

    fleet = tmp_path / "pair.yaml"
    fleet.write_text(f"fleet: pair\ndrones:\n  - {{name: d1, mission: {MISSIONS / 'figure10.xml'}, home: [0, 0]}}\n"
                     f"  - {{name: d2, mission: {MISSIONS / 'figure10.xml'}, home: [4, 0]}}\n")
    assert main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / "out")]) == 0
    for drone, mate in (("d1", "d2"), ("d2", "d1")):
        folder = tmp_path / "out" / drone
        assert disagreements(folder) == []  # a shared position in the journal alone would be a disagreement
        with Journal(folder) as journal:
            heard = journal.rows("SELECT record FROM events WHERE kind = 'fleet_drone_heard'")
            assert [json.loads(r["record"])["data"]["drones"] for r in heard] == [[mate]]
            assert journal.rows("SELECT count(*) FROM events WHERE record LIKE '%\"reason\":\"shared\"%'")[0][0] == 0
        capsys.readouterr()
        assert main(["journal", str(folder), "--belief", f"position({mate}, ?P)"]) == 0
        assert f"no change of position({mate}, ?P) in the journal" in capsys.readouterr().err
