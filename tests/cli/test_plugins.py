"""Behaviors, belief updaters and drone adapters from outside the package (issue 18, point 4): a tiny plugin
package with its own pyproject and entry points, pip-installed into a target folder on PYTHONPATH, flies with
``aeroexec run --catalog``; ``--library module:attribute`` adds behaviors without installing anything."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from aeroexec.engine.catalog import default_catalog_path
from aeroexec.engine.library import (
    LibraryError,
    aerial_behavior_names,
    behavior_names,
    default_library,
    default_updaters,
)

PYPROJECT = '''
[build-system]
requires = ["setuptools>=61"]
build-backend = "setuptools.build_meta"

[project]
name = "aeroexec-waggle"
version = "0.1.0"

[project.entry-points."aeroexec.behaviors"]
waggle = "aeroexec_waggle:behaviors"

[project.entry-points."aeroexec.updaters"]
waggle = "aeroexec_waggle:updaters"

[project.entry-points."aeroexec.drones"]
waggle-sim = "aeroexec_waggle:drone"
'''

MODULE = '''
"""WAGGLE_WINGS: roll left and right where the drone hovers; and an updater saying how high the drone is."""

from aeroexec.beliefs import BeliefUpdater
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess


class WaggleWings(BehaviorProcess):
    behavior = "WAGGLE_WINGS"

    def on_run(self):
        if self.elapsed >= float(self.arguments.get("SECONDS", 1.0)):
            self.memory.add("waggled(self, yes)")
            return Outcome.GOAL_ACHIEVED
        return None


class HeightBand(BeliefUpdater):
    def __init__(self, drone):
        super().__init__("height_band", period=0.2)
        self.drone = drone

    def update(self, memory, now):
        band = "high" if self.drone.telemetry().altitude > 2.5 else "low"
        memory.remove("height_band(self, ?b)")
        memory.add(f"height_band(self, {band})")


def behaviors():
    return [WaggleWings]


def updaters(drone):
    return [HeightBand(drone)]


def drone(address):
    from aeroexec.drones.sim import SimulatedDrone, default_world

    return SimulatedDrone(default_world(), seed=int(address or 0))
'''

CATALOG_ENTRY = '''- behavior: WAGGLE_WINGS
  description: Roll left and right where the drone is.
  arguments:
    - argument: SECONDS
      allowed_values: [0.5, 10]
'''
PREDICATES = '''- {predicate: waggled, arity: 2}
- {predicate: height_band, arity: 2}
'''

MISSION = '''
import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    assert api.execute_behavior("WAGGLE_WINGS", seconds=2) == api.GOAL_ACHIEVED
    assert api.true_belief("waggled(self, yes)") and api.true_belief("height_band(self, high)")
    api.execute_behavior("LAND")
'''


def write_plugin(root: Path) -> Path:
    package = root / "waggle"
    (package / "aeroexec_waggle").mkdir(parents=True)
    (package / "pyproject.toml").write_text(PYPROJECT)
    (package / "aeroexec_waggle" / "__init__.py").write_text(MODULE)
    return package


def write_catalog(root: Path) -> Path:
    text = default_catalog_path().read_text()
    text = text.replace("behavior_descriptors:\n", "behavior_descriptors:\n" + CATALOG_ENTRY, 1)
    text = text.replace("\npredicates:\n", "\npredicates:\n" + PREDICATES, 1)
    path = root / "waggle.yaml"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """The plugin pip-installed (built from its own pyproject) into a folder for PYTHONPATH."""
    root = tmp_path_factory.mktemp("plugin")
    target = root / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation",
                    "--target", str(target), str(write_plugin(root))], check=True, timeout=300,
                   capture_output=True, text=True)
    assert list(target.glob("aeroexec_waggle-*.dist-info/entry_points.txt"))
    return target


def aeroexec(*args: str, pythonpath: Path | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(pythonpath), env.get("PYTHONPATH")]))
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=300, env=env)


def test_an_installed_plugin_behavior_and_updater_fly(installed, tmp_path):
    catalog = write_catalog(tmp_path)
    mission = tmp_path / "waggle_mission.py"
    mission.write_text(MISSION)
    without = aeroexec("run", str(mission), "--catalog", str(catalog), "--plain", "--output", str(tmp_path / "a"))
    # without the plugin, the behavior is refused before flight, by name (issue 15: never "ready to fly")
    assert without.returncode == 1 and "WAGGLE_WINGS" in without.stderr and "will not fly" in without.stderr

    flown = aeroexec("run", str(mission), "--catalog", str(catalog), "--plain", "--output", str(tmp_path / "b"),
                     pythonpath=installed)
    assert flown.returncode == 0, flown.stderr
    assert "waggle_mission.py: completed at" in flown.stderr
    events = [json.loads(line) for line in (tmp_path / "b" / "events.jsonl").read_text().splitlines()]
    assert [e["kind"] for e in events if e.get("behavior") == "WAGGLE_WINGS"] == ["activated", "GOAL_ACHIEVED"]


def test_verify_names_a_catalog_behavior_with_no_implementation(installed, tmp_path):
    catalog = write_catalog(tmp_path)
    mission = tmp_path / "waggle_mission.py"
    mission.write_text(MISSION)
    bare = aeroexec("verify", "--catalog", str(catalog), str(mission))
    assert "warning: UNSUPPORTED: The behavior WAGGLE_WINGS is not supported by this robot" in bare.stdout
    plugged = aeroexec("verify", "--catalog", str(catalog), str(mission), pythonpath=installed)
    assert plugged.returncode == 0 and "UNSUPPORTED" not in plugged.stdout, plugged.stdout


def test_a_drone_adapter_from_an_entry_point(installed, tmp_path):
    catalog = write_catalog(tmp_path)
    mission = tmp_path / "ground.py"
    mission.write_text(textwrap.dedent('''
        import aeroexec.engine.api as api


        def mission():
            assert api.execute_behavior("WAGGLE_WINGS", seconds=0.5) == api.GOAL_ACHIEVED
        '''))
    flown = aeroexec("run", str(mission), "--catalog", str(catalog), "--drone", "waggle-sim:3", "--plain",
                     "--output", str(tmp_path / "c"), pythonpath=installed)
    assert flown.returncode == 0, flown.stderr
    unknown = aeroexec("run", str(mission), "--catalog", str(catalog), "--drone", "nosuch:1", "--plain",
                       "--output", str(tmp_path / "d"), pythonpath=installed)
    assert unknown.returncode == 1 and "no drone adapter is named 'nosuch'" in unknown.stderr
    assert "waggle-sim" in unknown.stderr


def test_library_references_add_behaviors_without_installing(tmp_path, monkeypatch):
    (tmp_path / "my_behaviors.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    library = default_library(["my_behaviors:behaviors"])
    aerial = default_library()
    assert "WAGGLE_WINGS" in library and "WAGGLE_WINGS" not in aerial
    assert library.names() == aerial.names() | {"WAGGLE_WINGS"}
    assert [u.name for u in default_updaters(object(), ["my_behaviors:updaters"])] == ["height_band"]
    with pytest.raises(LibraryError, match="my_behaviors:updaters failed: TypeError"):
        default_library(["my_behaviors:updaters"])
    with pytest.raises(LibraryError, match="gives no behaviors"):
        default_library(["my_behaviors:HeightBand.__doc__"])
    with pytest.raises(LibraryError, match="cannot import"):
        default_library(["no_such_module:x"])


def test_the_behavior_names_kept_in_the_cache_follow_the_behaviors_modules(tmp_path, monkeypatch):
    """verify reads the aerial library's behavior names from the user's cache folder; a behavior module added to the
    package (or changed) is read again, and references and plugins add theirs as the library does."""
    import aeroexec.engine.behaviors as package

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    aerial = default_library().names()
    assert aerial_behavior_names() == aerial  # read from the library, then kept
    assert aerial_behavior_names() == aerial  # read from the cache folder
    assert len(list((tmp_path / "cache" / "aeroexec").glob("behaviors.*.txt"))) == 1
    added = tmp_path / "added"
    added.mkdir()
    (added / "zz_waggle.py").write_text(textwrap.dedent('''
        from aeroexec.engine.execution.process import BehaviorProcess


        class Waggle(BehaviorProcess):
            behavior = "WAGGLE_IN_PLACE"
        '''))
    monkeypatch.setattr(package, "__path__", [*package.__path__, str(added)])
    monkeypatch.delitem(sys.modules, "aeroexec.engine.behaviors.zz_waggle", raising=False)
    try:
        assert aerial_behavior_names() == aerial | {"WAGGLE_IN_PLACE"}
    finally:
        sys.modules.pop("aeroexec.engine.behaviors.zz_waggle", None)
    (tmp_path / "my_behaviors.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert behavior_names(["my_behaviors:behaviors"]) == default_library(["my_behaviors:behaviors"]).names()
    with pytest.raises(LibraryError, match="cannot import"):
        behavior_names(["no_such_module:x"])
