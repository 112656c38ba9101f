"""The command follows the conventions users expect (issue 18, point 6): ``python -m aeroexec``, ``--version``,
shell completion, help texts that say what each command accepts, ``catalog`` without regard to case."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from aeroexec.engine.catalog import default_catalog

from aeroexec import __version__


def aeroexec(*args: str, env: dict[str, str] | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec", *args], capture_output=True, text=True, timeout=120,
                          env=env, cwd=cwd)


def test_python_m_aeroexec_and_version(tmp_path):
    help_text = aeroexec("--help", cwd=tmp_path)
    assert help_text.returncode == 0 and "usage: aeroexec" in help_text.stdout
    for command in ("run", "verify", "catalog", "ctl", "sim", "report"):
        assert command in help_text.stdout
    version = aeroexec("--version", cwd=tmp_path)
    assert version.returncode == 0 and version.stdout.strip() == f"aeroexec {__version__}"


def complete(line: str, tmp_path: Path) -> list[str]:
    """What the shell would offer after ``line`` (argcomplete's protocol, as its bash hook drives it)."""
    out = tmp_path / "completions.txt"
    env = dict(os.environ, _ARGCOMPLETE="1", COMP_LINE=line, COMP_POINT=str(len(line)),
               _ARGCOMPLETE_STDOUT_FILENAME=str(out), _ARGCOMPLETE_IFS="\n")
    result = aeroexec(env=env, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    return out.read_text().split()


def test_shell_completion_of_commands_options_and_behaviors(tmp_path):
    assert complete("aeroexec ve", tmp_path) == ["verify"]
    assert set(complete("aeroexec ctl p", tmp_path)) == {"pause"}
    assert "--max-time" in complete("aeroexec run --max", tmp_path)
    taking = {name for name in default_catalog().behaviors if name.startswith("TAKE_")}
    assert "TAKE_OFF" in taking and set(complete("aeroexec catalog TAKE_", tmp_path)) == taking
    (tmp_path / "survey_mission.py").write_text("")
    assert complete("aeroexec run surv", tmp_path) == ["survey_mission.py"]  # missions: the folder's files


def test_help_texts_say_what_each_command_accepts():
    run = aeroexec("run", "--help").stdout
    assert ".py" in run and "behavior tree" in run and ".tml.xml" in run and "BehaviorTree.CPP" in run
    assert "real time with the live view in a terminal" in " ".join(run.split())
    assert "--library" in run and "--drone" in run
    verify = aeroexec("verify", "--help").stdout
    assert "--world" in verify and "--no-world" in verify and ".tml.xml" in verify


def test_convert_help_names_every_format_it_writes():
    from aeroexec.cli.convert import FORMATS

    for text in (aeroexec("convert", "--help").stdout, aeroexec("--help").stdout):
        said = " ".join(text.split())
        assert "BehaviorTree.CPP v4 XML" in said and ".plan" in said and ".waypoints" in said, text
    assert set(FORMATS) == {"xml", "plan", "waypoints"}  # a format added is named in the help too


def test_what_the_commands_write_into_the_current_folder_is_git_ignored():

    from aeroexec.cli.main import build_parser
    from aeroexec.engine.supervision.output import DEFAULT_BASE

    ignored = set((Path(__file__).parents[2] / ".gitignore").read_text().split())
    parser = build_parser()
    defaults = {str(DEFAULT_BASE)}
    for sub in parser.commands.values():  # every command's --output folder by default
        for action in sub._actions:
            if "--output" in action.option_strings and isinstance(action.default, str):
                defaults.add(action.default)
    assert "aeroexec_rehearsal" in defaults
    assert {f"{name}/" for name in defaults} <= ignored, defaults


def test_catalog_ignores_case_and_lists_predicates_and_worlds():
    lower = aeroexec("catalog", "take_off")
    assert lower.returncode == 0 and "TAKE_OFF  (goal_based" in lower.stdout
    predicates = aeroexec("catalog", "--predicates")
    assert predicates.returncode == 0
    assert f"{len(default_catalog().predicates)} predicates" in predicates.stdout
    assert "minimum_distance_to_obstacle/2" in predicates.stdout and "(computed)" in predicates.stdout
    worlds = aeroexec("catalog", "--worlds")
    assert worlds.returncode == 0 and "default field (default)" in worlds.stdout
    assert "tower" in worlds.stdout and "40 x 40 x 20 m" in worlds.stdout
