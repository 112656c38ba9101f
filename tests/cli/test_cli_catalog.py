"""``aeroexec catalog`` from the installed package: the listing and ``--check`` with file:line."""

import subprocess
import sys
import sysconfig
from pathlib import Path

from aeroexec.engine.catalog import default_catalog

DATA = Path(__file__).parents[1] / "engine" / "data"


def aeroexec(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=60)


def test_the_console_script_is_installed():
    script = Path(sysconfig.get_path("scripts")) / "aeroexec"
    result = subprocess.run([str(script), "--version"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout.startswith("aeroexec ")


def test_catalog_lists_behaviors_with_categories_and_arguments():
    result = aeroexec("catalog")
    assert result.returncode == 0, result.stderr
    assert f"{len(default_catalog())} behaviors" in result.stdout
    assert "GO_TO_POINT  (goal_based, timeout 120 s)" in result.stdout
    assert "KEEP_HOVERING  (recurrent)" in result.stdout
    assert "{FORWARD, BACKWARD, LEFT, RIGHT, UPWARD, DOWNWARD}" in result.stdout
    assert "COORDINATES" in result.stdout and "POINT in the world (<= 5000 m from home, |z| <= 500 m)" in result.stdout


def test_catalog_shows_chosen_behaviors_and_rejects_unknown_ones():
    result = aeroexec("catalog", "TURN_LIGHTS")
    assert result.returncode == 0 and "MODE  {ON, OFF}  (required)" in result.stdout
    assert "GO_TO_POINT" not in result.stdout
    result = aeroexec("catalog", "TURN_LIGHT")
    assert result.returncode == 1
    assert "The behavior TURN_LIGHT does not exist (did you mean TURN_LIGHTS?)" in result.stderr
    assert "Traceback" not in result.stderr


def test_catalog_of_another_file():
    result = aeroexec("catalog", "--catalog", str(DATA / "appendix_b.yaml"))
    assert result.returncode == 0
    assert "15 behaviors" in result.stdout and "START_MOVING" in result.stderr


def test_check_a_good_catalog_prints_its_warnings():
    result = aeroexec("catalog", "--check", str(DATA / "appendix_b.yaml"))
    assert result.returncode == 0
    assert "appendix_b.yaml:126: warning:" in result.stdout
    assert "no errors, 5 warnings" in result.stdout


def test_check_a_bad_catalog_prints_every_error_with_its_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("behavior_descriptors:\n- behavior: LAND\n  timout: 3\n- behavior: LAND\n")
    result = aeroexec("catalog", "--check", str(bad))
    assert result.returncode == 1
    assert f"{bad}:3: error: behavior LAND: unknown key timout (did you mean timeout?)" in result.stdout
    assert f"{bad}:4: error: the behavior LAND is described twice (first at line 2)" in result.stdout
    assert "2 errors" in result.stdout and "Traceback" not in result.stderr


def test_check_a_missing_file():
    result = aeroexec("catalog", "--check", "no/such/catalog.yaml")
    assert result.returncode == 1 and "cannot read the file" in result.stdout
    assert "Traceback" not in result.stderr


def test_the_catalog_command_called_in_a_program_leaves_its_catalog_warnings_on(caplog, capsys):
    # the command prints the catalog's problems itself (its logger quiet meanwhile); a program that called it keeps
    # the catalog's warnings afterwards
    import logging

    from aeroexec.cli.main import main

    assert main(["catalog", "TAKE_OFF"]) == 0
    assert "TAKE_OFF" in capsys.readouterr().out
    logging.getLogger("aeroexec.engine.catalog").warning("heard after the command")
    assert "heard after the command" in caplog.text
