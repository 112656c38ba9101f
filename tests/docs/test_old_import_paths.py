"""The import paths of 0.1 forwarded for one release (0.2) are gone in 0.3: an old path is an ImportError naming
it, never a module that warns, and the version says the release."""

import importlib
import tomllib
from pathlib import Path

import pytest

import aeroexec

ROOT = Path(__file__).resolve().parents[2]
OLD = ["aeroexec.engine.specialist", "aeroexec.engine.coordinator", "aeroexec.engine.mission_bridge",
       "aeroexec.engine.supervision.flight_log", "aeroexec.drones.sim.mavlink_vehicle"]


@pytest.mark.parametrize("old", OLD)
def test_an_old_path_is_an_import_error_naming_it(old):
    with pytest.raises(ModuleNotFoundError, match=old.replace(".", r"\.")):
        importlib.import_module(old)


def test_the_version_is_the_release_without_the_old_paths():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert aeroexec.__version__ == declared
    assert tuple(int(part) for part in declared.split(".")[:2]) >= (0, 3)
