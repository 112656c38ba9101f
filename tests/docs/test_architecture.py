"""docs/ARCHITECTURE.md, claim by claim where a claim can be checked (issue 41): every path it names exists, every
package of its table is the folder it says and says its part in its ``__init__`` docstring, the layers it draws
are pyproject's import-linter contracts, the threads it names are the names the code gives them, a name it places
in a file is in that file, and "Where to add" has an entry for each thing a contributor adds."""

from __future__ import annotations

import ast
import importlib.util
import re
import subprocess
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
TEXT = (ROOT / "docs" / "ARCHITECTURE.md").read_text()
CONTRACTS = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
TRACKED = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
FILES = {Path(name) for name in TRACKED} | {p.relative_to(ROOT) for p in ROOT.rglob("*.py") if ".venv" not in p.parts}
FOLDERS = {parent for path in FILES for parent in path.parents}
#: A path in backquotes: a folder (``trees/runtime/``) or a source file (``engine/engine.py``, ``beliefs.lark``).
PATH = re.compile(r"`((?:[\w.-]+/)*[\w-]+(?:/|\.py|\.lark|\.toml|\.md))`")


def section(title: str) -> str:
    return TEXT.split(f"## {title}\n", 1)[1].split("\n## ", 1)[0]


def table_rows() -> list[tuple[list[str], list[str], str]]:
    """``(folders, packages, the rest)`` of each row of "The parts"."""
    rows = []
    for line in section("The parts").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 3 or not cells[0].startswith("`"):
            continue
        rows.append((re.findall(r"`([^`]+)`", cells[0]), re.findall(r"`(aeroexec[\w.]*)`", cells[1]),
                     " | ".join(cells[2:])))
    return rows


def exists(path: str, under: list[Path]) -> bool:
    """A path as written: from the repository's root, from one of the folders it is said of, or (a bare file
    name) anywhere below them."""
    bare = "/" not in path.rstrip("/")
    for base in [Path("."), *under]:
        target = base / path.rstrip("/")
        if target in FILES or target in FOLDERS:
            return True
        if bare and any(f.name == path and base in f.parents for f in FILES):
            return True
    return False


def test_every_path_the_table_names_exists():
    missing = []
    for folders, _packages, rest in table_rows():
        under = [Path(f.rstrip("/")) for f in folders if f.endswith("/")]
        under += [Path(f).parent for f in folders if f.endswith(".py")]
        for path in folders + PATH.findall(rest):
            if not exists(path, under):
                missing.append(f"{folders[0]}: {path}")
    assert missing == []


def test_every_path_named_elsewhere_exists():
    rest = TEXT.split("## The parts\n", 1)[0] + "\n## " + TEXT.split("## The parts\n", 1)[1].split("\n## ", 1)[1]
    missing = sorted({path for path in PATH.findall(rest) if not exists(path, [Path(".")])})
    assert missing == []


def test_each_package_of_the_table_is_its_folder_and_says_its_part():
    wrong = []
    for folders, packages, _rest in table_rows():
        for folder, package in zip(folders, packages, strict=False):
            spec = importlib.util.find_spec(package)
            if spec is None:
                wrong.append(f"{package}: not importable")
            elif folder.endswith("/"):
                location = Path(next(iter(spec.submodule_search_locations or [""])))
                if location.resolve() != (ROOT / folder).resolve():
                    wrong.append(f"{package} is {location}, not {folder}")
                init = ROOT / folder / "__init__.py"
                if not ast.get_docstring(ast.parse(init.read_text())):
                    wrong.append(f"{init.relative_to(ROOT)}: no docstring saying its part")
            elif folder.endswith(".py") and spec.origin and (ROOT / folder).resolve() not in (
                    Path(spec.origin).resolve(), *(Path(d).resolve() / Path(folder).name
                                                   for d in spec.submodule_search_locations or [])):
                wrong.append(f"{folder} is not {package}'s")
    assert wrong == []


def test_every_part_of_the_project_is_in_the_table():
    """Each top-level folder pyproject maps into ``aeroexec`` is a row (its sub-packages may be said inside)."""
    listed = {folder for folders, _packages, _rest in table_rows() for folder in folders}
    mapped = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"]
    folders = {f"{folder}/" for package, folder in mapped.items() if package != "aeroexec"}
    assert folders - listed == set()


def layers(text: str) -> list[str]:
    return [layer.strip() for layer in text.split("─▶")]


def contract(kind: str, **match) -> dict:
    found = [c for c in CONTRACTS if c["type"] == kind and all(c.get(k) == v for k, v in match.items())]
    assert len(found) == 1, (kind, match)
    return found[0]


def test_the_layers_drawn_are_the_import_contracts():
    drawing = section("Layers").split("```\n", 2)[1]
    outer = next(line for line in drawing.splitlines() if line.startswith("cli "))
    top = next(c for c in CONTRACTS if c["type"] == "layers" and "containers" not in c)
    assert layers(outer) == [layer.replace("aeroexec.", "") for layer in top["layers"]]
    inner = next(line for line in drawing.splitlines() if line.startswith("engine.engine "))
    engine = contract("layers", containers=["aeroexec.engine"])
    assert ["engine." + layers(inner)[0].split(".", 1)[1], *layers(inner)[1:]] == \
        ["engine." + engine["layers"][0], *engine["layers"][1:]]


def test_the_forbidden_imports_said_are_the_contracts():
    text = section("Layers")
    flight = next(c for c in CONTRACTS if c["type"] == "forbidden" and c["forbidden_modules"] == ["aeroexec.flight"])
    said = re.search(r"The engine is the engine: (.*?) never import `flight`", text, re.S).group(1)
    assert sorted(re.findall(r"`(\w+)`", said)) == sorted(m.replace("aeroexec.", "") for m in flight["source_modules"])
    core = next(c for c in CONTRACTS
                if c["type"] == "forbidden" and c["forbidden_modules"] == ["aeroexec.engine.behaviors"])
    said = re.search(r"The engine's core \((.*?)\)", text, re.S).group(1)
    named = {m.removesuffix(".py") for m in re.findall(r"`([\w.]+)`", said)}
    assert named == {m.replace("aeroexec.engine.", "") for m in core["source_modules"]}
    drones = next(c for c in CONTRACTS if c["type"] == "forbidden" and c["source_modules"] == ["aeroexec.drones"])
    assert "drones import nothing of the others" in text and len(drones["forbidden_modules"]) >= 7
    acyclic = contract("acyclic_siblings")
    assert "acyclic_siblings" in text and "one import is left out" in text
    assert len(acyclic.get("ignore_imports", [])) == 1


def test_the_threads_named_are_the_threads_the_code_starts():
    source = "\n".join((ROOT / f).read_text() for f in TRACKED if f.endswith(".py") and not f.startswith("tests/"))
    named = set(re.findall(r"thread `(aeroexec-[\w-]+)`|\(`(aeroexec-[\w-]+)`", TEXT))
    names = {a or b for a, b in named}
    assert names, "no thread named"
    missing = sorted(n for n in names if f'"{n}"' not in source)
    assert missing == []


#: "`NAME` (`path.py`...": a name the text places in a file.
PLACED = re.compile(r"`([A-Za-z_][\w.]*)` \(`((?:[\w-]+/)*[\w-]+\.py)`")


@pytest.mark.parametrize(("name", "path"), sorted(set(PLACED.findall(TEXT))))
def test_a_name_placed_in_a_file_is_there(name, path):
    candidates = [f for f in FILES if str(f) == path or (("/" not in path) and f.name == path)]
    assert candidates, path
    assert any(re.search(rf"\b{re.escape(name.split('.')[-1])}\b", (ROOT / f).read_text()) for f in candidates)


def test_where_to_add_names_each_thing_a_contributor_adds():
    entries = re.findall(r"^- \*\*(.+?)\*\*", section("Where to add things"), re.M)
    for thing in ("A behavior", "A built-in tree node", "A mission format", "A contingency", "A drone adapter",
                  "A dialect"):
        assert any(e.startswith(thing) for e in entries), thing


#: Names of BehaviorTree.CPP's that the text compares aeroexec's parts to.
BTCPP = {"TreeNodeManifest", "WriteTreeToXML", "Groot2Publisher"}


def test_every_code_name_it_names_is_defined():
    """``FlightSession.open``, ``tree_state.Capture``, ``Roster.trust``...: the last name of each is defined (a
    class, a function, an assignment, an attribute) in the package's code, or the rest is a module's path."""
    source = "\n".join((ROOT / f).read_text() for f in TRACKED if f.endswith(".py") and not f.startswith("tests/"))
    names = set()
    for token in re.findall(r"`([^`\n]+)`", TEXT):
        token = token.split("(")[0]
        suffix = token.rsplit(".", 1)[-1]
        dotted = re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)+", token) and not token.startswith("aeroexec") and \
            suffix not in {"py", "lark", "yaml", "toml", "md", "json", "jsonl", "btlog", "plan", "pem", "key", "sqlite",
                           "xml", "txt", "waypoints", "mission"}
        if dotted or re.fullmatch(r"[A-Z][a-z]+[A-Z]\w*", token):
            names.add(token)
    assert len(names) > 50
    undefined = []
    for name in sorted(names - BTCPP):
        last = re.escape(name.split(".")[-1])
        module = ROOT / name.replace(".", "/")
        if module.is_dir() or module.with_suffix(".py").is_file():
            continue
        if not re.search(rf"(class|def)\s+{last}\b|\b{last}\s*(:\s*[\w\[\]., |]+)?\s*=|self\.{last}\b", source):
            undefined.append(name)
    assert undefined == []


def test_every_table_or_constant_it_names_is_assigned():
    """``MANIFESTS``, ``BUILT_IN``, ``MEMORY``, ``CALLS_PER_TICK``, ``MISSION_SEEDS`` (of the fuzz suite)...: each is
    assigned somewhere in the repository's code."""
    source = "\n".join((ROOT / f).read_text(errors="replace") for f in TRACKED if f.endswith(".py"))
    constants = set(re.findall(r"`([A-Z][A-Z0-9_]{2,})`", TEXT))
    assert len(constants) > 5
    assert sorted(c for c in constants if not re.search(rf"\b{c}\s*(:\s*[^=\n]+)?=", source)) == []
