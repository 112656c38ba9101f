"""A mission format from outside the package (issue 41): a tiny distribution, one module and one entry point in the
group ``aeroexec.mission_formats``, pip-installed into a folder on PYTHONPATH. With it, and no file of aeroexec
touched, a ``.toy`` mission is listed in the help, verified (its mistakes at file:line), flown, converted to and
from BehaviorTree.CPP XML, and completed in the shell; without it, ``.toy`` is no mission file."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

PYPROJECT = '''
[build-system]
requires = ["setuptools>=61"]
build-backend = "setuptools.build_meta"

[project]
name = "aeroexec-toy-format"
version = "0.1.0"

[project.entry-points."aeroexec.mission_formats"]
toy = "aeroexec_toy_format:TOY"

[tool.setuptools]
py-modules = ["aeroexec_toy_format"]
'''

MODULE = '''
"""Toy missions: one behavior a line, its arguments as NAME=VALUE, flown in sequence (# starts a comment)."""

import re

from aeroexec.trees.formats import MissionFormat
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode

TOY = MissionFormat("Toy missions", (".toy",), "aeroexec_toy_format:read_toy", write="aeroexec_toy_format:write_toy",
                    writes_as="toy", summary="a toy mission")


def read_toy(data, file, home=None):
    text = data.decode("utf-8") if isinstance(data, bytes) else data
    leaves, problems = [], []
    for number, line in enumerate(text.splitlines(), 1):
        words = line.split("#", 1)[0].split()
        if not words:
            continue
        if not re.fullmatch(r"[A-Z][A-Z_]*", words[0]) or not all("=" in w for w in words[1:]):
            problems.append((file, number, f"expected BEHAVIOR NAME=VALUE..., not {line.strip()!r}"))
            continue
        ports = dict(w.split("=", 1) for w in words[1:])
        leaves.append(TreeNode(words[0], words[0], ports, [], file, number))
    if problems or not leaves:
        raise TreeFormatError(problems or [(file, 0, "no behavior in a toy mission")])
    return TreeDocument({"toy": TreeNode("Sequence", "toy", {}, leaves, file, leaves[0].line)}, "toy", file)


def write_toy(tree, catalog, home=None):
    lines = []
    for leaf in tree.root.children:
        lines.append(" ".join([leaf.type, *(f"{k}={v.replace(' ', '')}" for k, v in leaf.ports.items())]))
    return "\\n".join(lines) + "\\n"
'''

MISSION = """# up, one leg, home, down
TAKE_OFF ALTITUDE=3
GO_TO_POINT COORDINATES=4,0,3
GO_TO_POINT COORDINATES=0,0,3
LAND
"""


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """The toy format's distribution pip-installed (built from its own pyproject) into a folder for PYTHONPATH."""
    root = tmp_path_factory.mktemp("toy-format")
    (root / "pyproject.toml").write_text(textwrap.dedent(PYPROJECT))
    (root / "aeroexec_toy_format.py").write_text(MODULE)
    target = root / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation",
                    "--target", str(target), str(root)], check=True, timeout=300, capture_output=True, text=True)
    assert list(target.glob("aeroexec_toy_format-*.dist-info/entry_points.txt"))
    return target


def aeroexec(*args: str, pythonpath: Path | None = None, **extra: str) -> subprocess.CompletedProcess:
    env = {**os.environ, **extra}
    if pythonpath is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(pythonpath), env.get("PYTHONPATH")]))
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=300, env=env)


def test_the_help_lists_an_installed_format(installed):
    for command in (["--help"], ["verify", "--help"], ["run", "--help"], ["convert", "--help"]):
        said = " ".join(aeroexec(*command, pythonpath=installed).stdout.split())
        assert "Toy missions (.toy)" in said, command
        assert "Toy missions" not in aeroexec(*command).stdout, command  # the plugin is what adds it
    written = " ".join(aeroexec("convert", "--help", pythonpath=installed).stdout.split())
    assert "toy (a toy mission)" in written and "{xml,plan,waypoints,toy}" in written


def test_a_toy_mission_is_verified_and_its_mistakes_named_at_file_line(installed, tmp_path):
    mission = tmp_path / "leg.toy"
    mission.write_text(MISSION)
    refused = aeroexec("verify", str(mission))
    assert refused.returncode == 1 and f"{mission}: not a mission file" in refused.stdout

    checked = aeroexec("verify", str(mission), pythonpath=installed)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert f"{mission}: 0 errors" in checked.stdout and "ready to fly" in checked.stdout
    assert f"{mission}: route " in checked.stdout  # the route of its tree, as any tree format's

    wrong = tmp_path / "wrong.toy"
    wrong.write_text("TAKE_OFF ALTITUDE=3\ngo somewhere\nGO_TO_POINT COORDINATES=4,0,3\nLANDING\n")
    found = aeroexec("verify", str(wrong), pythonpath=installed)
    assert found.returncode == 1
    assert f"{wrong}:2: error: expected BEHAVIOR NAME=VALUE..., not 'go somewhere'" in found.stdout
    assert "Traceback" not in found.stdout + found.stderr


def test_a_toy_mission_flies(installed, tmp_path):
    mission = tmp_path / "leg.toy"
    mission.write_text(MISSION)
    flown = aeroexec("run", str(mission), "--plain", "--output", str(tmp_path / "run"), pythonpath=installed)
    assert flown.returncode == 0, flown.stderr
    assert "leg.toy: completed at" in flown.stderr
    events = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    achieved = [e["behavior"] for e in events if e.get("kind") == "GOAL_ACHIEVED"]
    assert achieved == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]


def test_a_toy_mission_converts_to_xml_and_back(installed, tmp_path):
    mission = tmp_path / "leg.toy"
    mission.write_text(MISSION)
    xml = tmp_path / "leg.xml"
    assert aeroexec("convert", str(mission), "-o", str(xml), pythonpath=installed).returncode == 0
    assert '<GO_TO_POINT COORDINATES="4,0,3"' in xml.read_text()
    back = tmp_path / "again.toy"  # the format to write from -o's extension, as for the built-in ones
    converted = aeroexec("convert", str(xml), "-o", str(back), pythonpath=installed)
    assert converted.returncode == 0, converted.stderr
    assert back.read_text().splitlines() == [line for line in MISSION.splitlines() if not line.startswith("#")]


def test_the_shell_completes_toy_missions(installed, tmp_path):
    (tmp_path / "leg.toy").write_text(MISSION)
    (tmp_path / "notes.md").write_text("not a mission")
    (tmp_path / "patrol.yaml").write_text("tree: {LAND: {}}\n")
    line = f"aeroexec verify {tmp_path}/"
    completion = {"_ARGCOMPLETE": "1", "_ARGCOMPLETE_IFS": "\n", "COMP_LINE": line, "COMP_POINT": str(len(line)),
                  "_ARGCOMPLETE_STDOUT_FILENAME": str(tmp_path / "completions")}
    aeroexec(pythonpath=installed, **completion)
    offered = sorted(Path(p).name for p in (tmp_path / "completions").read_text().split())
    assert offered == ["leg.toy", "patrol.yaml"]
