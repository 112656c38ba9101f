"""A tree node kind from outside the package (issue 41): a tiny distribution of two files, the kind's manifest (a
``NodeKind`` named by an entry point in the group ``aeroexec.node_kinds``) and its class, pip-installed into a folder
on PYTHONPATH. With it, and no file of aeroexec touched, a ``<Beep times="2"/>`` is listed in the help and the Groot2
palette, verified (a wrong port value at file:line), flown (its events in the run's log), converted to BehaviorTree.CPP
XML and back, and what it remembers is kept for a resume; without it, Beep is no node at all."""

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
name = "aeroexec-toy-node"
version = "0.1.0"

[project.entry-points."aeroexec.node_kinds"]
Beep = "toy_beep_kind:BEEP"

[tool.setuptools]
py-modules = ["toy_beep_kind", "toy_beep"]
'''

KIND = '''
"""The Beep node kind: its manifest (one port), the class that runs it, how the checks follow it."""

from aeroexec.trees.conversions import INT
from aeroexec.trees.runtime.kinds import NodeKind
from aeroexec.trees.runtime.manifests import InputPort, action

BEEP = NodeKind("Beep", action(InputPort("times", INT, "1", "beeps to make")), "toy_beep:Beep",
                memory=("beeped",), flow="pass", origin="aeroexec-toy-node")
'''

NODE = '''
"""Beep: SUCCESS once it has beeped ``times`` times, one beep a tick (each beep an event of the run)."""

from aeroexec.trees.runtime.nodes.actions import Leaf
from aeroexec.trees.runtime.ticking import RUNNING, SUCCESS
from toy_beep_kind import BEEP


class Beep(Leaf):
    manifest = BEEP.manifest

    def __init__(self, name, config):
        super().__init__(name, config)
        self.times = config.input("times", self.manifest.ports)
        self.beeped = 0

    def initialise(self):
        self.beeped = 0

    def update(self):
        if self.beeped >= self.times.get():
            return SUCCESS
        self.beeped += 1
        self.context.record("beep", f"beep {self.beeped}", node=self.name)
        return RUNNING
'''

MISSION = """<root BTCPP_format="4" main_tree_to_execute="M">
  <BehaviorTree ID="M">
    <Sequence>
      <TAKE_OFF ALTITUDE="3"/>
      <Beep name="hello" times="2"/>
      <GO_TO_POINT COORDINATES="4,0,3"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """The toy node's distribution pip-installed (built from its own pyproject) into a folder for PYTHONPATH."""
    root = tmp_path_factory.mktemp("toy-node")
    (root / "pyproject.toml").write_text(textwrap.dedent(PYPROJECT))
    (root / "toy_beep_kind.py").write_text(KIND)
    (root / "toy_beep.py").write_text(NODE)
    target = root / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation",
                    "--target", str(target), str(root)], check=True, timeout=300, capture_output=True, text=True)
    assert list(target.glob("aeroexec_toy_node-*.dist-info/entry_points.txt"))
    return target


def aeroexec(*args: str, pythonpath: Path | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(pythonpath), env.get("PYTHONPATH")]))
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=300, env=env)


def test_the_help_and_the_palette_list_an_installed_node_kind(installed, tmp_path):
    said = " ".join(aeroexec("--help", pythonpath=installed).stdout.split())
    assert "Tree node kinds added by installed packages: Beep (action, aeroexec-toy-node)." in said
    assert "Beep" not in aeroexec("--help").stdout  # the package is what adds it
    palette = tmp_path / "palette.xml"
    assert aeroexec("groot-model", "-o", str(palette), pythonpath=installed).returncode == 0
    assert '<Action ID="Beep">' in palette.read_text() and 'name="times" type="int"' in palette.read_text()


def test_a_tree_with_the_node_is_verified_and_its_mistakes_named_at_file_line(installed, tmp_path):
    mission = tmp_path / "beep.xml"
    mission.write_text(MISSION)
    refused = aeroexec("verify", str(mission))
    assert refused.returncode == 1
    assert f"{mission}:5: error: WRONG_FORMAT: The behavior Beep does not exist" in refused.stdout

    checked = aeroexec("verify", str(mission), pythonpath=installed)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert f"{mission}: 0 errors" in checked.stdout

    wrong = tmp_path / "wrong.xml"
    wrong.write_text(MISSION.replace('times="2"', 'times="two" volume="9"'))
    found = aeroexec("verify", str(wrong), pythonpath=installed)
    assert found.returncode == 1
    assert f"{wrong}:5: error: WRONG_VALUE: The value two of port times of node Beep is not correct" in found.stdout
    assert f"{wrong}:5: error: WRONG_FORMAT: The port volume of node Beep does not exist" in found.stdout
    assert "Traceback" not in found.stdout + found.stderr


def test_a_tree_with_the_node_flies(installed, tmp_path):
    mission = tmp_path / "beep.xml"
    mission.write_text(MISSION)
    flown = aeroexec("run", str(mission), "--plain", "--output", str(tmp_path / "run"), pythonpath=installed)
    assert flown.returncode == 0, flown.stderr
    assert "beep.xml: completed at" in flown.stderr
    events = [json.loads(line) for line in (tmp_path / "run" / "events.jsonl").read_text().splitlines()]
    assert [e["detail"] for e in events if e.get("kind") == "beep"] == ["beep 1", "beep 2"]
    achieved = [e["behavior"] for e in events if e.get("kind") == "GOAL_ACHIEVED"]
    assert achieved == ["TAKE_OFF", "GO_TO_POINT", "LAND"]


def test_a_tree_with_the_node_converts_to_xml_and_back(installed, tmp_path):
    mission = tmp_path / "beep.yaml"
    mission.write_text("tree:\n  Sequence:\n    - TAKE_OFF: {ALTITUDE: 3}\n    - Beep: {times: 2}\n    - LAND: {}\n")
    xml = tmp_path / "beep.xml"
    converted = aeroexec("convert", str(mission), "-o", str(xml), pythonpath=installed)
    assert converted.returncode == 0, converted.stderr
    assert '<Beep times="2" />' in xml.read_text() and '<Action ID="Beep">' in xml.read_text()  # and its model
    again = tmp_path / "again.xml"
    assert aeroexec("convert", str(xml), "-o", str(again), pythonpath=installed).returncode == 0
    assert again.read_text() == xml.read_text()
    refused = aeroexec("convert", str(mission), "-o", str(tmp_path / "not.xml"))
    assert refused.returncode == 1 and "The behavior Beep does not exist" in refused.stderr


def test_what_the_node_remembers_is_kept_for_a_resume(installed):
    code = "from aeroexec.trees.runtime.tree_state import MEMORY; print(MEMORY.get('Beep'))"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(installed), os.environ.get("PYTHONPATH")]))}
    shown = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert shown.stdout.split() == ["('beeped',)"], shown.stderr
