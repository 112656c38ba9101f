"""Real mission files from public repositories (data/real_missions/SOURCES.md): every multicopter mission flies in
the simulator at its own home, each of its items doing what it says (checked in the event log), and every other
one is refused with its item number and a reason a pilot understands."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from collections import defaultdict

import pytest
from aeroexec.drones.geodesy import geo_to_enu
from aeroexec.trees.items.behaviors import mission_home
from aeroexec.trees.items.readers import load_item_mission
from real_missions import DATA, FILES, REFUSED, checked, fly, name

FLYING = [p for p in FILES if name(p) not in REFUSED]
#: Items whose effect is on the items after them (a speed, a region of interest, a camera's trigger, a jump): they
#: have no behavior of their own to check.
SETTINGS = {177, 178, 189, 197, 205, 206, 214, 530, 2000, 2001, 2500, 2501, 114, 211, 203}
_ITEM = re.compile(r"^item (\d+) ")
_ALREADY = re.compile(r"already at \((-?[\d.]+), (-?[\d.]+),")  # a flight to where the drone already is


def _near(match: re.Match | None, point: tuple[float, float]) -> bool:
    return match is not None and math.dist((float(match.group(1)), float(match.group(2))), point) < 0.1


BESIDE = {"TRIGGER_CAMERA", "RECORD_VIDEO", "KEEP_LOITERING", "KEEP_HOVERING"}  # recurrent: never SUCCESS


def test_the_collection_has_25_files_or_more_from_8_repositories_or_more_each_with_its_commit():
    sources = (DATA / "SOURCES.md").read_text()
    rows = [line.split("|")[1:5] for line in sources.splitlines() if line.startswith("| ") and "/" in line
            and not line.startswith("| file")]
    listed = {cells[0].strip(): (cells[1].strip(), cells[3].strip()) for cells in rows}
    assert {name(p) for p in FILES} == set(listed)
    assert all(re.fullmatch(r"[0-9a-f]{40}", commit) for _, commit in listed.values())
    assert len(FILES) >= 25 and len({repo for repo, _ in listed.values()}) >= 8
    suffixes = {p.suffix for p in FILES}
    assert {".plan", ".waypoints", ".txt", ".mission"} <= suffixes
    assert any("complexItemType" in p.read_text() and "survey" in p.read_text() for p in FILES if p.suffix == ".plan")
    assert len(FLYING) >= 20


@pytest.mark.parametrize("path", [p for p in FILES if name(p) in REFUSED], ids=name)
def test_a_file_that_cannot_fly_is_refused_at_its_item_saying_why(path):
    expected = REFUSED[name(path)]
    errors = checked(path).errors
    assert errors, f"{name(path)} verifies"
    first = errors[0]
    assert first.file == str(path) and first.line > 0
    if expected.item is not None:
        assert first.message.startswith(f"item {expected.item}:") or f"item {expected.item}" in first.message[:20], \
            first.message
    assert expected.reason in first.message, first.message


def test_verify_says_it_at_file_line_with_the_item_and_exits_1():
    path = DATA / "ardupilot" / "aux_functions.txt"
    result = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "verify", str(path)], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 1
    assert f"{path}:4: error: WRONG_FORMAT: item 2: DO_AUX_FUNCTION switches an RC auxiliary function" in \
        result.stdout
    assert "1 error" in result.stdout and "will not fly" in result.stdout


@pytest.mark.parametrize("path", FLYING, ids=name)
def test_a_multicopter_mission_flies_every_item_where_it_is_planned(path, tmp_path):
    status, events, world, mission = fly(path, tmp_path)
    assert status.name == "SUCCESS", [str(e) for e in events if e.kind in ("WRONG_PROGRESS", "TIME_OUT",
                                                                            "FAILED_PRECONDITIONS", "rejected")]
    items = load_item_mission(path)
    home = mission_home(items)
    if home is not None:
        assert world.home[:2] == pytest.approx(home[:2], abs=1e-9)  # the world is at the mission's own home
    last: dict[str, str] = {}
    ended, ran = defaultdict(int), defaultdict(int)
    kinds: dict[str, str] = {}
    for event in events:
        if event.kind == "node_status":
            node = event.data["node"]
            last[node], kinds[node] = event.data["new"], event.data["type"]
            ended[node] += event.data["new"] == "SUCCESS"
            ran[node] += event.data["new"] == "RUNNING"
    by_item = defaultdict(list)
    for node, _ in last.items():
        match = _ITEM.match(node)
        if match:
            by_item[int(match.group(1))].append(node)
    for item in items.items:
        nodes = by_item.get(item.seq, [])
        if not nodes:
            assert item.command in SETTINGS, f"item {item.seq} ({item.name}) did nothing"
            continue
        beside = [n for n in nodes if kinds[n] in BESIDE]  # run until the items beside them end, then halted
        assert all(ended[n] >= 1 for n in nodes if n not in beside), (item.seq, {n: last[n] for n in nodes})
        assert all(ran[n] >= 1 for n in beside), (item.seq, {n: last[n] for n in nodes})
    for item in items.items:  # the drone flew to each waypoint's latitude and longitude, placed from its home
        if item.command == 16 and item.has_position():
            east, north, _ = geo_to_enu((item.latitude, item.longitude, 0.0), world.home)
            flown = [e for e in events if e.behavior == "GO_TO_POINT" and (
                e.kind == "activated" and math.dist(e.data["arguments"]["COORDINATES"][:2], (east, north)) < 0.05
                or e.kind == "GOAL_ACHIEVED" and _near(_ALREADY.search(e.detail), (east, north)))]
            assert flown, f"item {item.seq}: no flight to ({east:.1f}, {north:.1f})"
    for jump in (i for i in items.items if i.command == 177):  # a DO_JUMP flew its items again
        target = next(n for n in by_item[int(jump.params[0])])
        assert ended[target] == int(jump.params[1]) + 1
    if any(i.command == 206 and i.params[0] > 0 for i in items.items):
        assert [e for e in events if e.kind == "photo_taken" and e.behavior == "TRIGGER_CAMERA"]
