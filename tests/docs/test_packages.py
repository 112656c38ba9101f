"""The packages: found by the build from pyproject.toml's folder mapping alone (setup.py), never from a hand-kept
list; every package's face (its ``__init__.py``) in one style."""

from __future__ import annotations

import ast
import importlib
import importlib.util
import pkgutil
import subprocess
import sys
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


# Packages whose faces are not aeroexec's to shape: Aerostack's and Aerostack2's APIs as those projects have them
# (``rclpy``'s stand-in is its module), and the dialects' wing they move to.
FOREIGN = ("aeroexec.aerostack", "aeroexec.dialects", "aeroexec.trees.tml")
# Converted with the belief memory's own change (beliefs/ is reshaped apart).
LATER = ("aeroexec.beliefs",)


def _faces() -> dict[str, Path]:
    """Every package of the build with an ``__init__.py``: its name -> that file."""
    setup = _setup_module()
    faces = {}
    for package in setup.mapped_packages(ROOT):
        if package.startswith(FOREIGN + LATER):
            continue
        folder = setup._folder(ROOT, setup.tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
                                     ["package-dir"], package)
        if (folder / "__init__.py").is_file():
            faces[package] = folder / "__init__.py"
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
    imports = ["from typing import TYPE_CHECKING", "from aeroexec.lazy import lazy_names"]
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
