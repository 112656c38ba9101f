"""Installing aeroexec takes no name of ROS's or Aerostack's: its mission APIs are ``aeroexec.aerostack.<name>``,
and only the missions aeroexec loads import them as ``rclpy``, ``as2_python_api``, ``executive_engine_api``...
An environment with ROS 2 keeps its own ``rclpy`` for every other program, and for the program embedding aeroexec."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

from flying import EMPTY_WORLD

ROOT = Path(__file__).resolve().parents[2]
NAMES = ("rclpy", "as2_python_api", "as2_msgs", "executive_engine_api", "mission_execution_control")


def test_the_wheel_holds_every_module_of_the_source_and_nothing_outside_the_aeroexec_namespace(tmp_path):
    source = tmp_path / "src"
    source.mkdir()
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, source / name)
    for folder in set(project["tool"]["setuptools"]["package-dir"].values()):
        shutil.copytree(ROOT / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", str(source),
                    "-w", str(tmp_path / "dist")], check=True, capture_output=True, timeout=300)
    wheel, = (tmp_path / "dist").glob("aeroexec-*.whl")
    files = zipfile.ZipFile(wheel).namelist()
    assert {f.split("/")[0] for f in files} == {"aeroexec", wheel.name.split("-py")[0] + ".dist-info"}
    for name in ("rclpy/__init__.py", "as2_python_api/drone_interface.py", "as2_msgs/msg.py",
                 "executive_engine_api.py", "mission_execution_control.py"):
        assert f"aeroexec/aerostack/{name}" in files
    setuptools = project["tool"]["setuptools"]
    data = setuptools["package-data"]
    missing = []
    for package, folder in setuptools["package-dir"].items():  # a module or data file left out breaks `pip install .`
        for path in (ROOT / folder).rglob("*"):
            if not path.is_file() or "__pycache__" in path.parts or ".egg-info" in str(path):
                continue
            inner = path.relative_to(ROOT / folder)
            owner = ".".join([package, *inner.parent.parts])
            packaged = path.suffix == ".py" or any(path.match(pattern) for pattern in data.get(owner, ()))
            if packaged and "/".join([*package.split("."), *inner.parts]) not in files:
                missing.append(str(path.relative_to(ROOT)))
    assert not missing, f"not in the wheel (pyproject.toml's packages or package-data): {missing}"


SCRIPT = """\
import rclpy
from as2_python_api.drone_interface import DroneInterface

rclpy.init()  # ROS 2's would need a ROS graph
print("the mission's rclpy is up:", rclpy.ok())
uav = DroneInterface("drone0", verbose=False)
uav.offboard()
uav.arm()
uav.takeoff(2.0, speed=1.0)
uav.land(speed=0.5)
rclpy.shutdown()
"""

EMBEDDER = """\
import importlib.util, sys
names = {names!r}
before = {{n: importlib.util.find_spec(n) is not None for n in names}}
ros = "ros" in sys.argv
if ros:
    import rclpy as ros_rclpy  # the program's own, before any mission
from aeroexec.cli.main import main
status = main(["run", {mission!r}, "--plain", "--output", {out!r}, "--world", {world!r}])
import importlib
if ros:
    import rclpy
    print("the program's rclpy after the flight:", rclpy is ros_rclpy, rclpy.ROS_2)
after = {{n: n in sys.modules or importlib.util.find_spec(n) is not None for n in names}}
print("status", status, "before", sorted(n for n in names if before[n]), "after", sorted(n for n in names if after[n]))
"""


def embed(tmp_path: Path, *argv: str, ros_path: Path | None = None) -> str:
    """Fly :data:`SCRIPT` with ``aeroexec run`` from a program of its own in a fresh interpreter; what it printed."""
    mission = tmp_path / "script.py"
    mission.write_text(SCRIPT)
    program = tmp_path / "embedder.py"
    program.write_text(EMBEDDER.format(names=NAMES, mission=str(mission), out=str(tmp_path / "out"),
                                       world=str(EMPTY_WORLD)))
    env = {**os.environ, "PYTHONPATH": str(ros_path) if ros_path else ""}
    result = subprocess.run([sys.executable, str(program), *argv], capture_output=True, text=True, timeout=120,
                            cwd=tmp_path, env=env)
    assert result.returncode == 0 and "status 0" in result.stdout, result.stdout + result.stderr
    return result.stdout


def test_an_aerostack2_script_imports_the_api_while_no_program_finds_it_before_or_after(tmp_path):
    out = embed(tmp_path)
    assert "the mission's rclpy is up: True" in out
    assert "status 0 before [] after []" in out


def test_with_ros_2_installed_the_mission_gets_aeroexecs_rclpy_and_the_program_keeps_ros(tmp_path):
    ros = tmp_path / "ros"  # ROS 2's rclpy, as far as the import system can tell
    (ros / "rclpy").mkdir(parents=True)
    (ros / "rclpy" / "__init__.py").write_text("ROS_2 = True\n\ndef init():\n    raise RuntimeError('no ROS graph')\n")
    out = embed(tmp_path, "ros", ros_path=ros)
    assert "the mission's rclpy is up: True" in out
    assert "the program's rclpy after the flight: True True" in out
    assert "status 0 before ['rclpy'] after ['rclpy']" in out

