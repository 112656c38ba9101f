"""Replays are identical: every mission in ``missions/`` run in two processes with different string hashing
(PYTHONHASHSEED) writes the same event log, byte for byte."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from fleet_parts import fleet_parts

ROOT = Path(__file__).parents[2]
# every single-drone mission; a fleet's drones hear each other over Zenoh's threads, so a fleet replay is not
# promised to be byte-identical (the fleet tests check what the drones do instead)
MISSIONS = sorted(p for p in (ROOT / "missions").iterdir()
                  if p.suffix in (".py", ".xml", ".yaml") and p.name != "__init__.py"
                  and p.name not in fleet_parts(ROOT / "missions"))
HASH_SEEDS = ("1", "2")


def start(mission: Path, folder: Path, hash_seed: str) -> subprocess.Popen:
    """``aeroexec run mission --plain`` in ``folder`` (relative output paths, so both runs name files alike)."""
    folder.mkdir()
    env = {**os.environ, "PYTHONHASHSEED": hash_seed}
    return subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--plain", "--quiet",
                             "--output", "out", "--log", "events.jsonl"],
                            cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_the_missions_are_all_there():
    names = {p.name for p in MISSIONS}
    assert {"figure10.py", "figure10.xml", "square_patrol.yaml", "search_for_object.tml.xml"} <= names


def without_run_id(log: bytes) -> bytes:
    """The log with its first record's run id blanked: each run has its own (it ties the journal to its log), the
    one field two runs of the same mission and seed may not share."""
    first, newline, rest = log.partition(b"\n")
    blanked, count = re.subn(rb'"run":"run-[0-9a-f]{32}"', b'"run":"run-*"', first)
    assert count == 1, f"the first record names no run id: {first!r}"
    return blanked + newline + rest


@pytest.mark.parametrize("mission", MISSIONS, ids=[p.name for p in MISSIONS])
def test_two_processes_with_different_string_hashing_write_the_same_event_log(mission, tmp_path):
    runs = [(tmp_path / f"hash{seed}", start(mission, tmp_path / f"hash{seed}", seed)) for seed in HASH_SEEDS]
    logs = []
    for folder, process in runs:
        _, stderr = process.communicate(timeout=180)
        assert process.returncode == 0, f"{mission.name} with PYTHONHASHSEED={process.args}: {stderr}"
        logs.append(without_run_id((folder / "events.jsonl").read_bytes()))
    first, second = logs
    assert first.count(b"\n") > 20  # a real flight, not an empty log
    if first != second:
        lines = list(zip(first.splitlines(), second.splitlines(), strict=False))
        line, (a, b) = next((n, pair) for n, pair in enumerate(lines, 1) if pair[0] != pair[1])
        pytest.fail(f"{mission.name}: the event logs differ from line {line}:\n{a.decode()}\n{b.decode()}")
