"""examples/rover, installed as a package of its own: aeroexec embedded in a ground rover through the public API
and the ``aeroexec.robots`` entry point. Its missions (Python, tree, TML) run to completion; a reactive DOCK on
low battery preempts a mission; a WRONG_SEQUENCE is refused before the rover moves; it imports nothing private."""

import ast
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.drones.sim import load_world
from aeroexec.engine import Engine, load_catalog

ROVER = Path(__file__).parents[2] / "examples" / "rover"
MISSIONS = ROVER / "missions"
#: what an embedding robot may import of aeroexec (docs/embedding.md)
PUBLIC = {"aeroexec.engine", "aeroexec.engine.api", "aeroexec.engine.behaviors", "aeroexec.beliefs",
          "aeroexec.drones", "aeroexec.drones.sim"}

import aeroexec_rover as rover  # noqa: E402  (installed by .ci/run: pip install -e examples/rover)


def aeroexec(*args, cwd):
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=180)


@pytest.mark.parametrize("mission", ["patrol.py", "patrol.xml", "patrol.tml.xml"])
def test_each_rover_mission_runs_to_completion_with_robot_rover(mission, tmp_path):
    run = aeroexec("run", str(MISSIONS / mission), "--robot", "rover", "--plain", "--output", str(tmp_path / "out"),
                   cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert f"{mission}: completed" in run.stderr
    assert "GOAL_ACHIEVED DOCK" in run.stdout  # every patrol ends on the dock


def test_a_wrong_sequence_is_refused_before_the_rover_moves(tmp_path):
    run = aeroexec("run", str(MISSIONS / "wrong_sequence.xml"), "--robot", "rover", "--plain", "--output",
                   str(tmp_path / "out"), cwd=tmp_path)
    assert run.returncode == 1
    assert "wrong_sequence.xml:7: error: WRONG_SEQUENCE: The execution of behavior DOCK cannot be done" in run.stderr
    assert not (tmp_path / "out" / "events.jsonl").exists()  # nothing ran
    verify = aeroexec("verify", str(MISSIONS / "wrong_sequence.xml"), "--robot", "rover", cwd=tmp_path)
    assert verify.returncode == 1 and "will not run" in verify.stdout  # a rover does not fly


def test_an_unknown_robot_kind_is_named_with_the_installed_ones(tmp_path):
    run = aeroexec("run", str(MISSIONS / "patrol.py"), "--robot", "submarine", cwd=tmp_path)
    assert run.returncode == 2 and "no such robot kind" in run.stderr and "rover" in run.stderr


def test_low_battery_makes_the_rover_dock_whatever_the_mission_does():
    kind = rover.robot_kind()
    world = load_world(kind.world)
    robot = rover.SimulatedRover(world, config=rover.RoverConfig(battery=16.0), start=(-8, -8))
    engine = Engine(robot, catalog=load_catalog(kind.catalog), library=kind.behaviors(),
                    processes=kind.processes(), obstacles=world, telemetry=kind.telemetry(robot),
                    settings=kind.settings(), described_in=load_catalog(kind.catalog))
    spec = importlib.util.spec_from_file_location("rover_patrol", MISSIONS / "patrol.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    engine.run(module.mission, max_time=300, name="patrol.py")
    docks = engine.log.events(behavior="DOCK", kind="activated")
    assert docks and docks[0].data["source"] == "reactive" and docks[0].data["priority"] == "higher"
    interrupted = engine.log.events(behavior="DRIVE_TO_POINT", kind="INTERRUPTED")
    assert interrupted and interrupted[0].time == pytest.approx(docks[0].time, abs=0.1)
    assert engine.memory.holds("docked(self, yes)") and robot.docked


def test_the_rover_imports_only_aeroexecs_public_modules():
    used = set()
    for path in ROVER.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.module else []
            used |= {(n, str(path.relative_to(ROVER))) for n in names if n.split(".")[0] == "aeroexec"}
    assert used, "the rover uses aeroexec"
    private = sorted(f"{where}: {name}" for name, where in used if name not in PUBLIC)
    assert not private, private
