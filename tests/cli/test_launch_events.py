"""Events and alerts given at launch (``aeroexec run --event TOPIC=DATA``, ``--alert``): a tree that waits for
``WaitForEvent start`` (project_gazebo's square.xml) runs alone, as after ``aeroexec ctl add "event(start, go)"``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[2]
TREES = ROOT / "tests" / "aerostack" / "data" / "aerostack2_trees"
EMPTY_WORLD = ROOT / "tests" / "aerostack" / "data" / "empty_world.yaml"
SQUARE = TREES / "gazebo_square.xml"


def aeroexec(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=600, cwd=ROOT)


def test_a_tree_waiting_for_the_start_event_flies_alone_with_it_given_at_launch(tmp_path):
    run = aeroexec("run", str(SQUARE), "--world", str(EMPTY_WORLD), "--event", "start=go", "--quiet",
                   "--output", str(tmp_path / "run"))
    assert run.returncode == 0, run.stderr[-2000:]
    assert "at launch: added event(start, go)" in run.stderr and "gazebo_square.xml: completed at t=" in run.stderr
    records = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    flown = [r["arguments"]["COORDINATES"] for r in records
             if r["kind"] == "activated" and r["behavior"] == "GO_TO_POINT"]
    assert len(flown) == 4  # the square's four corners


def test_without_the_event_it_waits_until_the_time_limit_and_fails(tmp_path):
    run = aeroexec("run", str(SQUARE), "--world", str(EMPTY_WORLD), "--max-time", "20", "--quiet",
                   "--output", str(tmp_path / "run"))
    assert run.returncode == 1 and ": failed at t=" in run.stderr


def test_a_tree_waiting_for_an_event_nobody_gave_says_so_at_launch(tmp_path):
    """It does not wait silently: at its first tick the run prints one line naming the event, where the tree waits
    for it, and how to give it; given at launch, the line is not there."""
    run = aeroexec("run", str(SQUARE), "--world", str(EMPTY_WORLD), "--max-time", "5", "--plain",
                   "--output", str(tmp_path / "run"))
    assert run.returncode == 1
    said = [line for line in run.stdout.splitlines() if "] waiting: " in line]
    assert said == [f"[    0.00] waiting: gazebo_square.xml waits for event('start', ?) ({SQUARE}:6), which nothing "
                    f"has given: give it at launch with --event start=VALUE, or while it runs with aeroexec ctl add "
                    f"\"event('start', VALUE)\""]
    assert run.stdout.index("] waiting: ") < run.stdout.index("engine_time_limit")
    given = aeroexec("run", str(SQUARE), "--world", str(EMPTY_WORLD), "--event", "start=go", "--plain",
                     "--output", str(tmp_path / "given"))
    assert given.returncode == 0 and "] waiting: " not in given.stdout
    records = [json.loads(line) for line in (tmp_path / "given" / "events.jsonl").read_text().splitlines()]
    assert not [r for r in records if r["kind"] == "waiting"]


def test_an_alert_is_given_as_alert_topic_data(tmp_path):
    run = aeroexec("run", str(SQUARE), "--world", str(EMPTY_WORLD), "--event", "start=go", "--alert",
                   "/battery=low level", "--quiet", "--output", str(tmp_path / "run"))
    assert run.returncode == 0
    assert "at launch: added alert(battery, \"low level\")" in run.stderr


def test_an_event_without_a_topic_is_a_usage_error_naming_the_option(tmp_path):
    run = aeroexec("run", str(SQUARE), "--event", "=go", "--output", str(tmp_path / "run"))
    assert run.returncode == 2
    assert "--event =go: give TOPIC[=DATA]" in run.stderr and "Traceback" not in run.stderr
