"""A tree that cannot go on ticking (a script error, a port it cannot read) fails the run from the command line:
exit 1, naming the node and its line, inside a TryCatch too (BT.CPP 4.10's TryCatch does not catch exceptions)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def run(mission: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission)], capture_output=True,
                          text=True, timeout=120, cwd=mission.parent)


def test_a_script_error_fails_the_run_naming_the_node_and_line(tmp_path):
    mission = tmp_path / "broken.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M">\n<BehaviorTree ID="M">\n<Sequence>\n'
                       '<Script code="a := 1"/>\n<Script name="sum" code="x := y + 1"/>\n</Sequence>\n'
                       '</BehaviorTree>\n</root>\n')
    result = run(mission)
    assert result.returncode == 1, result.stdout + result.stderr
    error = f"tree_error: {mission}:5: Script 'sum': Error in script [x := y + 1]: Variable not found: y"
    assert error in result.stdout
    assert f"Script 'sum' failed at {mission}:5" in result.stderr and "broken.xml: failed" in result.stderr


def test_a_port_that_cannot_be_read_fails_the_run_even_inside_a_try_catch(tmp_path):
    """BT.CPP 4.10's TryCatch catches a child's FAILURE, not an exception: the error escapes the tick, exit 1."""
    mission = tmp_path / "caught.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M">\n<BehaviorTree ID="M">\n<Sequence>\n'
                       '<Script code="n := 2.5"/>\n<TryCatch>\n<Repeat num_cycles="{n}"><AlwaysSuccess/></Repeat>\n'
                       '<Script code="caught := 1"/>\n</TryCatch>\n</Sequence>\n</BehaviorTree>\n</root>\n')
    result = run(mission)
    assert result.returncode == 1, result.stdout + result.stderr
    assert f"tree_error: {mission}:6: Repeat: cannot read the port num_cycles from {{n}}" in result.stdout
    assert "caught by TryCatch" not in result.stdout
