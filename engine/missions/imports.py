"""The modules a Python mission imports that cannot be found: the mission would stop at its import.

Only absolute imports outside ``try`` blocks are judged (a mission may guard an optional import), by their
top-level package, without importing anything of the mission's. The modules a dialect serves, or judges by their
use (ROS modules), are left to it (:mod:`.standins`).
"""

from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

from aeroexec.engine.missions.standins import judged_by_use, stands_in


def _statements(body: list[ast.stmt]):
    for statement in body:
        if isinstance(statement, ast.Try | ast.TryStar):
            continue
        yield statement
        for field in ("body", "orelse", "finalbody"):
            inner = getattr(statement, field, None)
            if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                yield from _statements(inner)
        for case in getattr(statement, "cases", ()) or ():
            yield from _statements(case.body)


def missing_imports(tree: ast.Module, filename: str) -> list[tuple[ast.stmt, str]]:
    """``(statement, module)`` for each import whose top-level module is neither installed nor beside the file."""
    here = Path(filename).resolve().parent if filename and not filename.startswith("<") else None
    missing: list[tuple[ast.stmt, str]] = []
    for statement in _statements(tree.body):
        if isinstance(statement, ast.Import):
            names = [alias.name for alias in statement.names]
        elif isinstance(statement, ast.ImportFrom) and statement.module and not statement.level:
            names = [statement.module]
        else:
            continue
        for name in names:
            top = name.split(".")[0]
            if stands_in(name):
                continue  # aeroexec's own, as the mission imports it (standins)
            if judged_by_use(name):
                continue  # judged by what the mission uses of it (a dialect's check: ROS's)
            if not _found(top, here):
                missing.append((statement, top))
    return missing


def _found(top: str, here: Path | None) -> bool:
    try:  # a name no file system takes (longer than a file name may be) is no module beside the file
        if here is not None and ((here / f"{top}.py").exists() or (here / top / "__init__.py").exists()):
            return True
        return importlib.util.find_spec(top) is not None
    except (ImportError, ValueError, OSError):
        return False


__all__ = ["missing_imports"]
