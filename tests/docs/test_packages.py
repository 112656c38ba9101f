"""The packages: found by the build from pyproject.toml's folder mapping alone (setup.py), never from a hand-kept
list; every package's face (its ``__init__.py``) in one style."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _setup_module():
    spec = importlib.util.spec_from_file_location("aeroexec_setup", ROOT / "setup.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # not __main__: nothing is built
    return module


def _write(path: Path, text: str = "") -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def test_a_new_folder_with_an_init_ships_from_the_mapping_alone(tmp_path):
    _write(tmp_path / "pyproject.toml", '[tool.setuptools.package-dir]\n"aeroexec" = "aeroexec"\n'
                                        '"aeroexec.dialects" = "dialects"\n'
                                        '[tool.setuptools.package-data]\n"aeroexec.dialects.tml.static" = ["*.js"]\n')
    _write(tmp_path / "aeroexec" / "__init__.py")
    _write(tmp_path / "dialects" / "__init__.py")
    _write(tmp_path / "dialects" / "tml" / "__init__.py")
    _write(tmp_path / "dialects" / "tml" / "reader" / "__init__.py")
    _write(tmp_path / "dialects" / "tml" / "static" / "page.js")  # a data folder package-data names
    _write(tmp_path / "dialects" / "notes" / "deep" / "__init__.py")  # under a folder that is no package
    _write(tmp_path / "dialects" / "__pycache__" / "x.pyc")
    assert _setup_module().mapped_packages(tmp_path) == [
        "aeroexec", "aeroexec.dialects", "aeroexec.dialects.tml", "aeroexec.dialects.tml.reader",
        "aeroexec.dialects.tml.static"]


def test_the_build_finds_every_package_of_the_repository():
    found = set(_setup_module().mapped_packages(ROOT))
    assert {"aeroexec", "aeroexec.flight.journal", "aeroexec.trees.runtime.nodes", "aeroexec.console.static"} <= found
    outside = {".venv", "tests", "examples", "bench", "tools", "docs", "build"}
    folders = {init.parent for init in ROOT.rglob("__init__.py")
               if not outside & set(init.relative_to(ROOT).parts) and ".egg-info" not in str(init)}
    assert len(found) == len(folders) + 1  # and console/static, a data folder
