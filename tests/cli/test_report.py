"""The event log of a run, ``aeroexec report``, the Groot2 ``.btlog`` of tree runs, ``aeroexec beliefs``, and a log
that survives the engine being killed."""

import json
import os
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from aeroexec.cli.reporting.style import PATH_COLOR, RETURN_COLOR
from aeroexec.trees.groot.btlog import STATUS_CODES, read_btlog
from PIL import Image

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"


def aeroexec(*args: str, cwd: Path = ROOT, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=120, cwd=cwd, input=stdin)


def records_of(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.fixture(scope="module")
def tree_run(tmp_path_factory) -> Path:
    """figure10.xml flown on the simulator into an output folder of its own."""
    folder = tmp_path_factory.mktemp("tree_run")
    result = aeroexec("run", str(MISSIONS / "figure10.xml"), "--output", str(folder), "--quiet")
    assert result.returncode == 0, result.stderr + result.stdout
    assert f"event log: {folder / 'events.jsonl'}" in result.stderr
    return folder


def test_every_run_writes_an_event_log_of_events_beliefs_and_state_samples(tree_run):
    records = records_of(tree_run / "events.jsonl")  # every line parses
    assert records[0]["kind"] == "log_started" and records[0]["mission"] == "figure10.xml"
    assert records[-1]["kind"] == "log_closed" and records[-1]["lines"] == len(records)
    kinds = [r["kind"] for r in records]
    assert kinds.index("engine_started") < kinds.index("mission_completed") < kinds.index("engine_stopped")
    go = [r for r in records if r["kind"] == "activated" and r["behavior"] == "GO_TO_POINT"]
    assert go[0]["arguments"]["COORDINATES"] == [2, 5, 1.3] and go[0]["data"]["source"] == "mission"
    assert {r["behavior"] for r in records if r["kind"] == "GOAL_ACHIEVED"} >= {"TAKE_OFF", "GO_TO_POINT", "LAND"}
    assert all("reason" in r for r in records if r["kind"] in ("GOAL_ACHIEVED", "INTERRUPTED"))
    added = [r for r in records if r["kind"] == "belief_added"]
    removed = [r for r in records if r["kind"] == "belief_removed"]
    assert any(r["belief"] == "flight_state(self, flying)" or r["belief"].startswith("flight_state(") for r in added)
    assert removed and all(r["reason"] in ("add", "remove", "replaced", "expired", "clear") for r in removed)
    samples = [r for r in records if r["kind"] == "state"]
    assert set(samples[0]) == {"time", "kind", "position", "velocity", "yaw", "battery", "armed", "landed_state"}
    gaps = [b["time"] - a["time"] for a, b in zip(samples, samples[1:-1], strict=False)]
    assert gaps and all(0.45 <= gap <= 0.55 for gap in gaps)  # 2 Hz
    assert max(s["position"][2] for s in samples) > 1.0 and samples[-1]["landed_state"] == "on_ground"
    times = [r["time"] for r in records]
    assert times == sorted(times)


def test_the_report_draws_the_path_and_a_timeline_and_summarizes_in_html(tree_run):
    result = aeroexec("report", str(tree_run / "events.jsonl"))
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == [str(tree_run / name) for name in ("path.png", "flight.png", "timeline.png",
                                                                       "report.html")]
    with Image.open(tree_run / "path.png") as image:
        assert image.format == "PNG" and 1100 <= image.size[0] <= 1400 and 700 <= image.size[1] <= 900
        pixels = np.asarray(image.convert("RGB"), dtype=int)[:, :int(0.66 * image.size[0])]  # the map, not the legend
        for color in (PATH_COLOR, RETURN_COLOR):  # the path flown: 5 m out, then back, each leg in its color
            wanted = np.array([int(color[i:i + 2], 16) for i in (1, 3, 5)])
            near = int((np.abs(pixels - wanted).sum(axis=2) < 30).sum())
            assert near > 50, color
    with Image.open(tree_run / "flight.png") as image:
        assert image.format == "PNG" and image.size[0] >= 1000
    with Image.open(tree_run / "timeline.png") as image:
        assert image.format == "PNG" and 1000 <= image.size[0] <= 1300
    page = (tree_run / "report.html").read_text()
    for name in ("TAKE_OFF", "GO_TO_POINT", "LAND", "GOAL_ACHIEVED", "distance flown", "battery used"):
        assert name in page
    assert page.count("<svg") == 3 and "completed" in page  # the images inline, their labels as text
    assert all(f"href='{name}'" in page for name in ("path.png", "flight.png", "timeline.png"))


def test_a_tree_run_writes_a_groot2_btlog_in_the_current_fileloggers2_format(tree_run):
    data = (tree_run / "mission.btlog").read_bytes()
    assert data.startswith(b"BTCPP4-FileLogger2\x01")
    (size,) = struct.unpack_from("<i", data, 19)
    assert data[23:23 + size].decode().startswith('<root BTCPP_format="4">\n    <BehaviorTree ID=')
    log = read_btlog(tree_run / "mission.btlog")
    nodes = log.nodes()
    assert sorted(nodes) == list(range(1, 8))  # figure10.xml: a Sequence and 6 leaves
    assert nodes[1] == ("Sequence", "figure 10") and nodes[7] == ("LAND", "LAND")
    assert abs(log.first_timestamp_usec / 1e6 - time.time()) < 600
    assert len(log.transitions) == (len(data) - 23 - size - 8) // 9
    statuses = [r for r in records_of(tree_run / "events.jsonl") if r["kind"] == "node_status"]
    # every change the run reported is in the file at its engine time; BT.CPP's resets to IDLE come on top
    logged = {(t.usec, t.uid, t.status) for t in log.transitions}
    for event in statuses:
        assert (round(event["time"] * 1e6), event["data"]["uid"], STATUS_CODES[event["data"]["new"]]) in logged
    last = [(t.uid, t.status_name) for t in log.transitions if t.usec == log.transitions[-1].usec]
    assert last == [(7, "SUCCESS"), *[(uid, "IDLE") for uid in range(2, 8)], (1, "SUCCESS"), (1, "IDLE")]
    assert "<TreeNodesModel>" in log.xml and '<Action ID="GO_TO_POINT"' in log.xml


def test_beliefs_answers_queries_against_the_final_state_of_a_log(tree_run):
    log = str(tree_run / "events.jsonl")
    result = aeroexec("beliefs", log, stdin="flight_state(self, ?S)\nlist armed\n"
                                                      "charge(battery, ?C), ?C > 200\nobject(?X\nquit\n")
    assert result.returncode == 0, result.stderr
    assert "?S" in result.stdout and "landed" in result.stdout  # the table of unifications
    assert "armed(self, no)" in result.stdout  # the run ends once the drone says it is disarmed
    assert "charge(battery, ?C), ?C > 200: no" in result.stdout
    assert "object(?X:" in result.stderr and "Traceback" not in result.stderr
    one_shot = aeroexec("beliefs", log, "--query", "code(?Marker, ?Id)")
    assert one_shot.returncode == 0 and "marker_1" in one_shot.stdout


def test_a_python_mission_writes_no_btlog_and_log_can_name_the_file(tmp_path):
    log = tmp_path / "elsewhere" / "flight.jsonl"
    result = aeroexec("run", str(MISSIONS / "figure10.py"), "--output", str(tmp_path / "out"), "--log", str(log),
                      "--quiet")
    assert result.returncode == 0, result.stderr
    assert records_of(log)[-1]["kind"] == "log_closed"
    assert not (tmp_path / "out" / "mission.btlog").exists() and not (tmp_path / "out" / "events.jsonl").exists()


def test_without_output_the_run_gets_a_dated_folder_of_its_own(tmp_path):
    for _ in range(2):
        result = aeroexec("run", str(MISSIONS / "figure10.xml"), "--quiet", cwd=tmp_path)
        assert result.returncode == 0, result.stderr
    folders = sorted((tmp_path / "aeroexec_output").iterdir())
    assert len(folders) == 2 and all((f / "events.jsonl").exists() and (f / "mission.btlog").exists()
                                     for f in folders)
    beliefs = aeroexec("beliefs", "-q", "flight_state(self, ?S)", cwd=tmp_path)  # the newest log by default
    assert beliefs.returncode == 0 and "landed" in beliefs.stdout


def test_killing_the_engine_mid_mission_leaves_a_log_of_whole_lines_up_to_the_kill(tmp_path):
    log = tmp_path / "events.jsonl"
    process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", str(MISSIONS / "figure10.py"),
                                "--speed", "1", "--output", str(tmp_path), "--quiet"], cwd=ROOT,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and (not log.exists() or log.read_text().count("\n") < 40):
            time.sleep(0.05)
        seen = records_of_whole_lines(log)
        time.sleep(1.0)
        os.kill(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
    finally:
        if process.poll() is None:
            process.kill()
    text = log.read_text()
    assert text.endswith("\n")  # no torn line
    records = [json.loads(line) for line in text.splitlines()]  # every line parses
    assert records[0]["kind"] == "log_started" and len(records) > len(seen) >= 40
    assert not any(r["kind"] in ("log_closed", "engine_stopped", "mission_completed") for r in records)
    # the log went on until the kill: state samples kept coming during the last second
    assert records[-1]["time"] >= seen[-1]["time"] + 0.5
    assert records[-1]["time"] - max(r["time"] for r in records if r["kind"] == "state") <= 0.6


def records_of_whole_lines(path: Path) -> list[dict]:
    text = path.read_text()
    return [json.loads(line) for line in text[:text.rfind("\n") + 1].splitlines()]


def test_the_report_counts_refused_requests_and_plots_altitude_speed_battery(tmp_path):
    """Issue 18, point 8: FAILED_PRECONDITIONS in the outcomes table, the run's status word, flight states."""
    from aeroexec.flight.flight_log import read_flight_log
    from aeroexec.flight.summary import summarize

    mission = tmp_path / "refused.py"
    mission.write_text(
        "import aeroexec.engine.api as api\n\n\ndef mission():\n"
        "    api.execute_behavior('TAKE_OFF', altitude=3)\n    x = int('5')  # computed: verify leaves it to the run\n"
        "    api.execute_behavior('GO_TO_POINT', coordinates=(x, x, 3))\n"
        "    api.execute_behavior('GO_TO_POINT', coordinates=(-4, 0, 3))\n    api.execute_behavior('LAND')\n")
    run = aeroexec("run", str(mission), "--output", str(tmp_path / "out"), "--quiet")
    assert run.returncode == 3, run.stderr
    summary = summarize(read_flight_log(tmp_path / "out" / "events.jsonl"))
    assert summary.outcome == "completed with refused requests"
    assert summary.outcome_counts()["GO_TO_POINT"] == {"FAILED_PRECONDITIONS": 1, "GOAL_ACHIEVED": 1}
    states = [state for _, state in summary.flight_states]
    assert states[:2] == ["landed", "taking_off"] and "moving" in states and states[-1] == "landed"
    series = summary.series()
    assert max(series["altitude"]) == pytest.approx(3, abs=0.3) and max(series["speed"]) > 1
    assert series["battery"][0] > series["battery"][-1]
    result = aeroexec("report", str(tmp_path / "out" / "events.jsonl"))
    assert result.returncode == 0 and "completed with refused requests" in result.stderr
    page = (tmp_path / "out" / "report.html").read_text()
    outcomes = page.split("<h2>Outcomes by behavior</h2>")[1].split("<h2>")[0]
    assert "<th>FAILED_PRECONDITIONS</th>" in outcomes and "completed with refused requests" in page
