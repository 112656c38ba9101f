"""The files users look for in a project (issue 18, point 9): LICENSE as pyproject names it, CHANGELOG for the
version, ``py.typed`` in the installed package, an index of the example missions, and no reference to a file
outside the repository."""

from __future__ import annotations

import re
import subprocess
import tomllib
from importlib import resources
from pathlib import Path

ROOT = Path(__file__).parents[2]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def test_license_is_the_mit_text_pyproject_names():
    assert PROJECT["license"] == "MIT" and PROJECT["license-files"] == ["LICENSE"]
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License") and "Permission is hereby granted, free of charge" in text
    assert 'THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND' in text


def test_changelog_has_the_current_version():
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## [{PROJECT['version']}]" in changelog and "## [Unreleased]" in changelog


def test_the_package_is_typed():
    assert (resources.files("aeroexec") / "py.typed").is_file()


def test_missions_readme_lists_every_example_mission_and_only_them():
    folder = ROOT / "missions"
    missions = {p.name for p in folder.iterdir() if p.suffix in (".py", ".xml", ".yaml", ".yml", ".plan")
                and p.name != "__init__.py"}
    linked = set(re.findall(r"\]\(([^)]+)\)", (folder / "README.md").read_text()))
    assert missions <= linked and {link for link in linked if "/" not in link} <= missions


def test_no_reference_to_a_file_outside_the_repository():
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    outside = re.compile(r"(?<![\w.])(/work/|shared/DESIGN|seeds/\d)")
    offenders = []
    for name in tracked.splitlines():
        path = ROOT / name
        if path.suffix not in (".py", ".md", ".toml", ".yaml", ".xml", ".txt", ".cfg", "") or not path.is_file():
            continue
        if name.startswith("tests/docs/test_project_files.py"):
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        offenders += [f"{name}: {m.group(0)}" for m in outside.finditer(text)]
        if path.suffix == ".md":  # relative links resolve inside the repository
            for link in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text):
                target = (path.parent / link).resolve()
                if not target.exists() or ROOT.resolve() not in target.parents and target != ROOT.resolve():
                    offenders.append(f"{name}: link {link}")
    assert offenders == []
