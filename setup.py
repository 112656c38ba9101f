"""The packages of the wheel, found from pyproject.toml's folder mapping (``[tool.setuptools.package-dir]``): every
folder under a mapped one that has an ``__init__.py`` is the package its path names (``engine/catalog/`` is
``aeroexec.engine.catalog``), and a data folder without one is a package when ``[tool.setuptools.package-data]``
names it (``aeroexec.console.static``). Everything else about the build is in pyproject.toml; setuptools' own discovery
cannot map the top-level folders into ``aeroexec``, so this walk replaces a hand-kept list that once shipped a
wheel without ``aeroexec.flight.journal``."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

from setuptools import setup

HERE = Path(__file__).resolve().parent


def mapped_packages(root: Path = HERE) -> list[str]:
    """Every package under the folders pyproject.toml maps, by the folder mapping alone."""
    setuptools = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    mapping = setuptools["package-dir"]
    found = {package for package in setuptools.get("package-data", {}) if _folder(root, mapping, package).is_dir()}
    for package, folder in mapping.items():
        top = root / folder
        for here, folders, files in os.walk(top):
            if "__init__.py" not in files:
                folders.clear()  # a folder that is not a package holds none (data, caches)
                continue
            folders.sort()
            found.add(".".join([package, *Path(here).relative_to(top).parts]))
    return sorted(found)


def _folder(root: Path, mapping: dict[str, str], package: str) -> Path:
    """The folder of ``package`` by the mapping of its nearest mapped ancestor."""
    parts = package.split(".")
    for cut in range(len(parts), 0, -1):
        if (top := ".".join(parts[:cut])) in mapping:
            return root.joinpath(mapping[top], *parts[cut:])
    return root.joinpath(*parts)


if __name__ == "__main__":
    setup(packages=mapped_packages())
