"""Missions that choose through derived beliefs: one drone picks its landing pad by rules; a fleet shares a
derived predicate."""

from __future__ import annotations

import json
import re
from pathlib import Path

from aeroexec.cli.main import main

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


def events(folder: Path) -> list[dict]:
    return [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]


def test_the_drone_lands_on_the_pad_its_rules_choose(tmp_path, capsys):
    assert main(["run", str(MISSIONS / "land_by_rules.py"), "--plain", "--output", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "landing on pad_c, because:" in out  # pad_a and pad_b have things on them, pad_d is gusty
    assert "not(taken(pad_c))  <- no belief matches it" in out
    assert re.search(r"taken\(pad_a\)  <- the rule at land_by_rules\.py:\d+", out)
    log = events(tmp_path)
    landed = [e for e in log if e["kind"] == "GOAL_ACHIEVED" and e.get("behavior") == "LAND"]
    assert landed and any(e["kind"] == "mission_completed" for e in log)
    last = [e for e in log if e.get("behavior") == "GO_TO_POINT" and e["kind"] == "activated"][-1]
    assert last["arguments"]["COORDINATES"] == [2, -8, 4], last


def test_a_fleet_shares_a_derived_predicate(tmp_path, capsys):
    code = main(["fleet", str(MISSIONS / "pad_survey.yaml"), "--plain", "--output", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    heard = [e for e in events(tmp_path / "lander") if e["kind"] == "fleet_belief"]
    assert any("free_pad(scout, pad_c, 2, -8)" in e["detail"] for e in heard), heard
    assert not any("pad_a" in e["detail"] or "pad_b" in e["detail"] for e in heard)
    assert "landing on pad_c, found free by scout" in out
    summary = next(line for line in err.splitlines() if line.startswith("lander:"))
    assert "completed" in summary and re.search(r"landed at \(2\.0, -8\.\d\)", summary), summary
