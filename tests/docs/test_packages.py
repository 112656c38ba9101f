"""The packages: found by the build from pyproject.toml's folder mapping alone (setuptools' discovery of an explicit
``package-dir`` layout), never from a hand-kept list; every package's face (its ``__init__.py``) in one style."""

from __future__ import annotations

import ast
import importlib
import pkgutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def _write(path: Path, text: str = "") -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def test_no_package_is_listed_by_hand():
    setuptools = PROJECT["tool"]["setuptools"]
    assert "packages" not in setuptools and not (ROOT / "setup.py").exists()
    assert setuptools["package-dir"]["aeroexec.flight"] == "flight"


def test_a_new_mapped_folder_ships_with_its_packages_from_the_mapping_alone(tmp_path):
    """What the build relies on, as this setuptools does it: a project mapped as aeroexec's is (a top-level folder
    to ``aeroexec.<name>``, nothing listed) ships every package under the folder, a data folder's files too."""
    _write(tmp_path / "pyproject.toml", '[build-system]\nrequires = ["setuptools>=77"]\n'
                                        'build-backend = "setuptools.build_meta"\n'
                                        '[project]\nname = "mapped"\nversion = "1.0"\n'
                                        '[tool.setuptools.package-dir]\n"aeroexec" = "aeroexec"\n'
                                        '"aeroexec.dialects" = "dialects"\n'
                                        '[tool.setuptools.package-data]\n"aeroexec.dialects.tml.static" = ["*.js"]\n')
    _write(tmp_path / "aeroexec" / "__init__.py")
    _write(tmp_path / "dialects" / "__init__.py")
    _write(tmp_path / "dialects" / "tml" / "__init__.py")
    _write(tmp_path / "dialects" / "tml" / "journal" / "__init__.py")
    _write(tmp_path / "dialects" / "tml" / "journal" / "reader.py")
    _write(tmp_path / "dialects" / "tml" / "static" / "page.js")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", str(tmp_path),
                    "-w", str(tmp_path / "dist")], check=True, capture_output=True, timeout=300)
    wheel, = (tmp_path / "dist").glob("mapped-*.whl")
    files = set(zipfile.ZipFile(wheel).namelist())
    assert {"aeroexec/__init__.py", "aeroexec/dialects/__init__.py", "aeroexec/dialects/tml/__init__.py",
            "aeroexec/dialects/tml/journal/reader.py", "aeroexec/dialects/tml/static/page.js"} <= files


# Packages whose faces are not aeroexec's to shape: Aerostack's and Aerostack2's APIs as those projects have them
# (``rclpy``'s stand-in is its module), and the dialects' wing they move to.
FOREIGN = ("aeroexec.dialects",)
# Converted with the belief memory's own change (beliefs/ is reshaped apart).
LATER = ("aeroexec.beliefs",)


def _faces() -> dict[str, Path]:
    """Every package under the mapped folders (a folder with an ``__init__.py``): its name -> that file."""
    faces = {}
    for package, folder in PROJECT["tool"]["setuptools"]["package-dir"].items():
        for init in sorted((ROOT / folder).rglob("__init__.py")):
            name = ".".join([package, *init.parent.relative_to(ROOT / folder).parts])
            if not name.startswith(FOREIGN + LATER):
                faces[name] = init
    return faces


def _lazy_face(package: str, tree: ast.Module) -> dict[str, str] | None:
    """The names and modules of a lazy face (``aeroexec.lazy``), None for an empty one; AssertionError naming the
    package and line of anything else."""
    body = tree.body[1:]
    if package == "aeroexec":  # the distribution's version, besides
        assert [ast.unparse(node.targets[0]) for node in body[:1]] == ["__version__"], "aeroexec: its __version__"
        body = body[1:]
    if not body:
        return None
    shape = [ast.unparse(node).splitlines()[0] for node in body]
    imports = ["from aeroexec.lazy import lazy_names", "TYPE_CHECKING = False"]  # typing costs --help its import
    assert len(body) == 5 and shape[:2] == imports, f"{package}: neither a docstring alone nor a lazy face: {shape}"
    names_node, getattr_node, checking = body[2], body[3], body[4]
    assert ast.unparse(names_node.targets[0]) == "__all__", f"{package}:{names_node.lineno}: __all__ first"
    exported = ast.literal_eval(names_node.value)
    assert exported == sorted(exported), f"{package}:{names_node.lineno}: __all__ sorted"
    call = getattr_node.value
    assert (ast.unparse(getattr_node.targets[0]) == "__getattr__" and isinstance(call, ast.Call)
            and ast.unparse(call.func) == "lazy_names" and ast.unparse(call.args[0]) == "__name__"), \
        f"{package}:{getattr_node.lineno}: __getattr__ = lazy_names(__name__, {{...}})"
    modules = ast.literal_eval(call.args[1])
    assert set(modules) == set(exported), f"{package}: __all__ and lazy_names name different things"
    assert ast.unparse(checking.test) == "TYPE_CHECKING" and not checking.orelse, f"{package}:{checking.lineno}"
    typed = {}
    for node in checking.body:
        assert isinstance(node, ast.ImportFrom), f"{package}:{node.lineno}: only imports under TYPE_CHECKING"
        typed |= {alias.name: node.module for alias in node.names if alias.asname is None}
    assert typed == {name: f"{package}.{module}" for name, module in modules.items()}, \
        f"{package}: the TYPE_CHECKING imports are not the lazy names from their modules"
    return modules


def test_every_package_face_is_lazy_names_or_its_docstring_alone():
    faces = _faces()
    assert {"aeroexec", "aeroexec.engine", "aeroexec.flight.journal", "aeroexec.cli"} <= set(faces)
    lazy = empty = 0
    for package, path in faces.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        assert ast.get_docstring(tree), f"{path}: a package says its part in its docstring"
        modules = _lazy_face(package, tree)
        if modules is None:
            empty += 1
            continue
        lazy += 1
        submodules = {info.name for info in pkgutil.iter_modules([str(path.parent)])}
        assert not set(modules) & submodules, \
            f"{path}: a lazy name that is also a module's name turns into the module once that module is imported"
    assert lazy >= 15 and empty >= 15


def test_every_lazy_name_resolves_to_its_module_s_object():
    for package, path in _faces().items():
        modules = _lazy_face(package, ast.parse(path.read_text(encoding="utf-8"))) or {}
        face = importlib.import_module(package)
        for name, module in modules.items():
            assert getattr(face, name) is getattr(importlib.import_module(f"{package}.{module}"), name), \
                f"{package}.{name}"


def test_importing_every_package_face_imports_no_module_behind_them():
    packages = sorted(_faces())
    probe = ("import importlib, sys\n"
             f"for package in {packages!r}:\n"
             "    importlib.import_module(package)\n"
             "print('\\n'.join(m for m in sys.modules if m.startswith('aeroexec') and m not in "
             f"{packages!r} and m != 'aeroexec.lazy'))\n")
    imported = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert imported.split() == []
