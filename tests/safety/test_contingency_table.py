"""Contingencies are one table (issue 41): a contingency from outside the package (one class, registered by an
``aeroexec.contingencies`` entry point of a distribution on ``sys.path``) is read from a rules file, checked by
``verify`` with the file and line of a mistake, named in ``--help``, and taken in a simulated flight, whose end
finishes it before landing; the docs' list of contingencies (docs/safety.md) is the table's."""

from __future__ import annotations

import json
import re
import sys
import textwrap
from pathlib import Path

import pytest
from aeroexec.cli.main import main
from aeroexec.engine.catalog import default_catalog, engine_behaviors
from aeroexec.engine.catalog.contingencies import BUILT_IN, contingency_kinds
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text, rule_vocabulary

from aeroexec.plugins import installed

PAGE = Path(__file__).resolve().parents[2] / "docs" / "safety.md"

TOY = '''
"""CLIMB METERS: a toy contingency from outside aeroexec: climb that much above where the drone is, and hover."""

from aeroexec.engine.catalog.contingencies import Contingency, ContingencyKind, point_text
from aeroexec.engine.catalog.engine_behaviors import KEEP_HOVERING


class Climb(ContingencyKind):
    name, syntax, severity = "climb", "climb METERS", 1
    description = "climbs that many meters above where the drone is, and hovers"
    finish_before_landing, lands_where = True, "climbed to"

    def parse(self, arguments, names):
        try:
            meters = float(arguments[0]) if len(arguments) == 1 else 0.0
        except ValueError:
            meters = 0.0
        if meters <= 0:
            return f"climb needs a height in meters above 0 (not {' '.join(arguments) or 'none'!r})"
        return Contingency(self.name, f"{meters:g}")

    def act(self, contingency, actions):
        actions.take_over()
        here = actions.here()
        if here is None:
            return actions.land()
        point = (here[0], here[1], here[2] + float(contingency.target))
        actions.fly_to(point, then=KEEP_HOVERING)
        return f"climbing to {point_text(point)}"


class Tumble(ContingencyKind):
    name, syntax = "tumble", "tumble"

    def act(self, contingency, actions):
        raise RuntimeError("the toy tumbles")
'''

FENCED = '''import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=5)
    ok, here = api.consult_belief("position(self, (?x, ?y, ?z))")
    api.execute_behavior("GO_TO_POINT", coordinates=[here["x"] + 15, here["y"], 5])  # out through the fence
    api.execute_behavior("LAND")  # refused: the rule has the drone
'''

RULES = """# the field's rules
- rule: fence
  always: position(self, (?x, ?y, ?z)), ?x > -10, ?x < 10, ?y > -10, ?y < 10
  contingency: {contingency}
"""


@pytest.fixture
def toy_contingency(tmp_path, monkeypatch):
    """A distribution ``toy-climb`` on sys.path: one module with one class, one entry point; no aeroexec file
    touched. The entry points and the table are read again with it, and without it after the test."""
    site = tmp_path / "site"
    (site / "toy_climb-0.1.dist-info").mkdir(parents=True)
    (site / "toy_climb.py").write_text(TOY)
    (site / "toy_climb-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-climb\n"
                                                                 "Version: 0.1\n")
    (site / "toy_climb-0.1.dist-info" / "entry_points.txt").write_text(
        "[aeroexec.contingencies]\nclimb = toy_climb:Climb\ntumble = toy_climb:Tumble\n")
    monkeypatch.syspath_prepend(str(site))
    installed.cache_clear()
    contingency_kinds.cache_clear()
    yield site
    sys.modules.pop("toy_climb", None)
    installed.cache_clear()
    contingency_kinds.cache_clear()


def write(path: Path, text: str) -> Path:
    path.write_text(textwrap.dedent(text))
    return path


def test_a_contingency_from_an_installed_package_is_checked_shown_and_flown(toy_contingency, tmp_path, capsys):
    mission = write(tmp_path / "fenced.py", FENCED)
    wrong = write(tmp_path / "wrong.yaml", RULES.format(contingency="climb high"))
    assert main(["verify", str(mission), "--safety-rules", str(wrong)]) == 1
    out = capsys.readouterr().out
    assert f"{wrong}:4: error: safety rule fence: climb needs a height in meters above 0 (not 'high')" in out, out
    assert "Traceback" not in out

    with pytest.raises(SystemExit):
        main(["verify", "--help"])
    assert "climb METERS" in " ".join(capsys.readouterr().out.split()), "--help lists the plugin's contingency"

    rules = write(tmp_path / "rules.yaml", RULES.format(contingency="climb 4"))
    assert main(["verify", str(mission), "--safety-rules", str(rules)]) == 0, capsys.readouterr().out
    capsys.readouterr()

    out_dir = tmp_path / "out"
    assert main(["run", str(mission), "--safety-rules", str(rules), "--quiet", "--output", str(out_dir)]) == 1
    records = [json.loads(line) for line in (out_dir / "events.jsonl").read_text().splitlines()]
    (violated,) = [r for r in records if r["kind"] == "safety_violated"]
    assert violated["data"]["contingency"] == "climb 4"
    climbed = re.fullmatch(r"climbing to \((.+), (.+), (.+)\)", violated["data"]["action"])
    assert climbed and float(climbed[3]) == pytest.approx(9.0, abs=0.3), violated["data"]["action"]
    (held,) = [r for r in records if r["kind"] == "ending_held"]
    assert "lands where it climbed to" in held["detail"], "the end of the mission finished the climb first"
    kinds = [r["kind"] for r in records]
    climb = next(i for i, r in enumerate(records) if r["kind"] == "GOAL_ACHIEVED"
                 and r.get("behavior") == "GO_TO_POINT" and r["data"].get("source") == "safety")
    arrived = [r["data"]["position"] for r in records[:climb] if r["kind"] == "drone_arrived"]
    assert arrived and arrived[-1][2] == pytest.approx(9.0, abs=0.3), "the drone climbed 4 m above 5 m"
    assert kinds.index("ending_held") < climb < kinds.index("landing") < kinds.index("drone_landed"), \
        "the end of the mission let the climb finish, then landed"
    (ended,) = [r for r in records if r["kind"] == "run_ended"]
    assert ended["detail"] == "failed" and ended["data"]["reasons"][0].startswith("safety rule fence broken at t=")


def test_a_contingency_that_fails_lands_the_drone_and_says_why(toy_contingency, tmp_path):
    mission = write(tmp_path / "fenced.py", FENCED)
    rules = write(tmp_path / "rules.yaml", RULES.format(contingency="tumble"))
    out_dir = tmp_path / "out"
    assert main(["run", str(mission), "--safety-rules", str(rules), "--quiet", "--output", str(out_dir)]) == 1
    records = [json.loads(line) for line in (out_dir / "events.jsonl").read_text().splitlines()]
    (violated,) = [r for r in records if r["kind"] == "safety_violated"]
    assert violated["data"]["action"] == ("its contingency failed (RuntimeError: the toy tumbles); landing where "
                                          "it is")
    kinds = [r["kind"] for r in records]
    landing = next(i for i, r in enumerate(records) if r["kind"] == "activated" and r.get("behavior") == "LAND")
    assert records[landing]["data"]["source"] == "safety", "the contingency's own landing, not the run's end"
    assert kinds.index("safety_violated") < kinds.index("mission_completed") and "drone_landed" in kinds


@pytest.mark.parametrize("contingency, words", [
    ("retrun home", "unknown contingency 'retrun home' (did you mean return?) (one of hold, return [home], land, "
                    "subtree ID, call FUNCTION)"),
    ("hold here", "the contingency hold takes no argument (not 'here')"),
    ("return away", "the contingency return takes nothing or home (not 'away')"),
    ("subtree", "the contingency subtree takes the name of one subtree (subtree ID)"),
    ("subtree Dock", "the contingency names the subtree Dock, which the mission does not have"),
    ("call go home", "the contingency call takes the name of one mission function (call FUNCTION, not 'go home')"),
], ids=["unknown", "hold", "return", "subtree", "no such subtree", "call"])
def test_a_built_in_contingency_with_wrong_arguments_is_refused_at_its_line(contingency, words):
    found = read_safety_rules_text(RULES.format(contingency=contingency), "field.yaml", rule_vocabulary(
        {"position": 2}), subtrees=["Main"], functions=["go_home"])
    assert not found.rules
    assert [(p.file, p.line, p.message) for p in found.problems] == [
        ("field.yaml", 4, f"safety rule fence: {words}")]


def test_a_plugin_cannot_replace_a_built_in_contingency(tmp_path, monkeypatch):
    site = tmp_path / "site"
    (site / "toy_land-0.1.dist-info").mkdir(parents=True)
    (site / "toy_land.py").write_text("from aeroexec.engine.catalog.contingencies import Land\n\n\n"
                                      "class Sideways(Land):\n    description = 'lands somewhere else'\n")
    (site / "toy_land-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-land\nVersion: 0.1\n")
    (site / "toy_land-0.1.dist-info" / "entry_points.txt").write_text(
        "[aeroexec.contingencies]\nland = toy_land:Sideways\n")
    monkeypatch.syspath_prepend(str(site))
    installed.cache_clear()
    contingency_kinds.cache_clear()
    try:
        assert contingency_kinds()["land"].description == "lands where the drone is"
    finally:
        sys.modules.pop("toy_land", None)
        installed.cache_clear()
        contingency_kinds.cache_clear()


def test_the_readme_lists_the_contingencies_of_the_table():
    """The table of contingencies (docs/safety.md) is the built-in table: every word, its form and what it does."""
    text = PAGE.read_text()
    table = text.split("<!-- contingencies -->\n")[1].split("\n\n")[0]
    rows = re.findall(r"^\| `([^`]+)` \| (.+?) \|$", table, re.M)
    assert rows == [(kind.syntax, kind.description) for kind in BUILT_IN]


def test_the_behaviors_the_engine_requests_by_itself_are_the_aerial_catalogs():
    """A contingency flies, hovers and lands by the names in engine_behaviors.py: each is a behavior of the
    catalog, or a hold would be refused in flight and the drone would land instead."""
    catalog = default_catalog()
    missing = [name for name in engine_behaviors.__all__ if getattr(engine_behaviors, name) not in catalog]
    assert not missing, f"not in the aerial catalog: {missing}"
