"""The foreign dialects' wing (dialects/, ``aeroexec.dialects``): Aerostack, Aerostack2 and TML register with the core
through entry points only, as an outside package would; the core imports none of them, reads, checks and flies its
own formats without them, and the wheel ships them with their entry points."""

from __future__ import annotations

import ast
import configparser
import json
import shutil
import subprocess
import sys
import tomllib
import zipfile
from importlib.metadata import entry_points
from pathlib import Path

from aeroexec.plugins import load_reference

ROOT = Path(__file__).resolve().parents[2]
CORE = ("engine", "trees", "beliefs", "grammar", "drones", "flight", "fleet")
#: group -> the dialects' entry points in it
REGISTERED = {
    "aeroexec.mission_formats": {"aerostack", "aerostack2", "tml"},
    "aeroexec.mission_imports": {"aerostack", "aerostack2", "ros"},
    "aeroexec.mission_checks": {"aerostack", "aerostack2", "ros"},
    "aeroexec.catalog_dialects": {"aerostack"},
    "aeroexec.xml_documents": {"tml"},
    "aeroexec.yaml_forms": {"nodes"},
    "aeroexec.tree_mappings": {"aerostack2"},
    "aeroexec.tree_verifiers": {"tml"},
}


def test_each_dialect_registers_through_entry_points_that_name_objects_of_the_wing():
    for group, names in REGISTERED.items():
        found = {p.name: p.value for p in entry_points(group=group) if p.value.startswith("aeroexec.dialects.")}
        assert set(found) == names, group
        for value in found.values():
            assert load_reference(value) is not None, value


def test_no_module_of_the_core_imports_a_dialect():
    imports = []
    for folder in CORE:
        for path in (ROOT / folder).rglob("*.py"):
            text = path.read_text(encoding="utf-8")
            if "dialects" not in text:  # no import of it can be there (parsed only where one may be)
                continue
            for node in ast.walk(ast.parse(text)):
                names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                         [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
                imports += [f"{path.relative_to(ROOT)}: {n}" for n in names if n.startswith("aeroexec.dialects")]
    assert imports == []


WITHOUT_DIALECTS = """
import json
import sys
import aeroexec.plugins as plugins

everything = plugins._entries_on_path(tuple(sys.path))


def without_dialects(path):  # the installed entry points but the dialects'
    return {group: [(name, value) for name, value in points if not value.startswith("aeroexec.dialects.")]
            for group, points in everything.items()}


plugins._entries_on_path = without_dialects

from aeroexec.engine.missions.check import check_mission_source
from aeroexec.trees import load_mission_tree
from aeroexec.trees.formats import described, format_of

levant = "import executive_engine_api as api\\n\\ndef runMission():\\n    api.executeBehavior('TAKE_OFF')\\n"
own = open("missions/inspection.py").read()
print(json.dumps({
    "formats": described(),
    "tml_file": format_of("m.tml.xml").name,
    "json_file": format_of("m.json") is None,
    "xml_tree": sorted(load_mission_tree("missions/figure10.xml").trees),
    "yaml_tree": sorted(load_mission_tree("missions/square_patrol.yaml").trees),
    "own_mission": [p.message for p in check_mission_source(own, "inspection.py") if p.severity == "error"],
    "levant_mission": [p.message for p in check_mission_source(levant, "levant.py") if p.severity == "error"],
}))
"""


def test_without_the_dialects_the_core_reads_and_checks_its_own_formats_and_knows_none_of_theirs():
    done = subprocess.run([sys.executable, "-c", WITHOUT_DIALECTS], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert "TML" not in seen["formats"] and "Aerostack" not in seen["formats"]
    assert seen["formats"].startswith("Python missions (.py), BehaviorTree.CPP XML (.xml), YAML trees")
    assert seen["tml_file"] == "BehaviorTree.CPP XML" and seen["json_file"]
    assert seen["xml_tree"] and seen["yaml_tree"]
    assert seen["own_mission"] == []
    assert seen["levant_mission"] == ["The module executive_engine_api cannot be found: the mission would stop at "
                                      "this import"]


def test_the_wheel_ships_the_dialects_and_declares_their_entry_points(tmp_path):
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
    archive = zipfile.ZipFile(wheel)
    files = set(archive.namelist())
    declared = configparser.ConfigParser()
    declared.read_string(archive.read(next(f for f in files if f.endswith(".dist-info/entry_points.txt"))).decode())
    for group, names in REGISTERED.items():
        assert names <= set(declared[group]), group
        for name in names:
            module = declared[group][name].partition(":")[0]
            assert f"{module.replace('.', '/')}.py" in files, (group, name)
