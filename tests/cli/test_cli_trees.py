"""Behavior-tree missions from the command line: verify, run to success, refuse what is wrong, Groot2 palette."""

import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"
RUNS = tempfile.TemporaryDirectory(prefix="aeroexec-runs-")  # where runs write their output folders


def aeroexec(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=120, cwd=RUNS.name)


TREES = ["figure10.xml", "square_patrol.yaml", "iarc7.xml", "iarc7.yaml", "survey_legs.xml"]


def test_every_tree_mission_verifies():
    result = aeroexec("verify", *(str(MISSIONS / m) for m in TREES))
    assert result.returncode == 0, result.stdout
    assert result.stdout.count("0 errors, 0 warnings; ready to fly") == len(TREES)


@pytest.mark.parametrize("mission", TREES)
def test_tree_missions_run_to_success_and_show_the_tree(mission):
    result = aeroexec("run", str(MISSIONS / mission))
    assert result.returncode == 0, result.stderr + result.stdout
    assert f"{mission}: completed" in result.stderr
    lines = result.stdout.splitlines()
    assert any("] tree " in line and "-> RUNNING" in line for line in lines)  # statuses as they change
    assert any("] tree   LAND: RUNNING -> SUCCESS" in line or "LAND: RUNNING -> SUCCESS" in line for line in lines)
    assert "mission_completed" in result.stdout


def test_iarc7_lands_on_the_target():
    result = aeroexec("run", str(MISSIONS / "iarc7.xml"))
    landed = [line for line in result.stdout.splitlines() if "drone_landed" in line][-1]
    x, y = (float(v) for v in landed.split("at (")[1].rstrip(")").split(","))
    assert abs(x + 13) < 0.5 and abs(y + 15) < 0.5


def test_survey_legs_flies_both_subtree_legs_skips_the_detour_and_switches_home():
    """A SubTree port given a literal, Script, Switch, _skipIf and _onSuccess, as BehaviorTree.CPP runs them."""
    result = aeroexec("run", str(MISSIONS / "survey_legs.xml"), "--plain")
    assert result.returncode == 0, result.stderr + result.stdout
    out = result.stdout
    arrivals = [line.split("at (")[1].rstrip(")") for line in out.splitlines() if "drone_arrived" in line]
    assert arrivals[:3] == ["3.0, 0.0, 2.0", "3.0, 3.0, 2.0", "0.0, 0.0, 2.0"]  # both legs, then straight home
    assert "detour: IDLE -> SKIPPED" in out  # _skipIf: legs >= 2, counted by each leg's _onSuccess
    assert "straight home: RUNNING -> SUCCESS" in out and "home by the detour" not in out
    assert "both legs flown: IDLE -> SUCCESS" in out  # _onSuccess set back := 'home'
    assert "survey_legs.xml: completed" in result.stderr


def test_a_wrong_tree_is_refused_with_every_problem_and_its_line(tmp_path):
    mission = tmp_path / "wrong.xml"
    mission.write_text(
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="Main">\n'
        '    <Sequence>\n'
        '      <LAND/>\n'
        '      <TAKE_OF/>\n'
        '      <GO_TO_POINT COORDINATES="1, 2"/>\n'
        '      <Condition belief="charge(battery, ?X"/>\n'
        '      <GO_TO_POINT COORDINATES="{target}"/>\n'
        '    </Sequence>\n'
        '  </BehaviorTree>\n'
        '</root>\n')
    result = aeroexec("run", str(mission))
    assert result.returncode == 1 and "the mission will not fly" in result.stderr
    for line, words in [(4, "The execution of behavior LAND cannot be done at the start of the mission"),
                        (5, "TAKE_OF"), (6, "The value"), (7, "The format of the belief expression"),
                        (8, "target")]:
        assert any(f"wrong.xml:{line}:" in text and words in text for text in result.stderr.splitlines()), \
            (line, result.stderr)
    assert "activated" not in result.stdout and "Traceback" not in result.stderr


def test_a_billion_laughs_file_is_refused_not_expanded(tmp_path):
    mission = tmp_path / "laughs.xml"
    mission.write_text('<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
                       '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">]>\n'
                       '<root BTCPP_format="4"><BehaviorTree ID="M"><LAND name="&lol2;"/></BehaviorTree></root>\n')
    result = aeroexec("verify", str(mission))
    assert result.returncode == 1 and "laughs.xml:2" in result.stdout and "Traceback" not in result.stderr


def test_groot_model_writes_the_palette(tmp_path):
    out = tmp_path / "palette.xml"
    result = aeroexec("groot-model", "-o", str(out))
    assert result.returncode == 0 and '<Action ID="GO_TO_POINT"' in out.read_text()
