"""The mission APIs aeroexec stands in for, under the names missions import them by: a table the dialects fill.

A mission written for another system imports that system's API by its own names (Aerostack's
``executive_engine_api``, Aerostack2's ``rclpy`` and ``as2_python_api``...). A dialect (``aeroexec.dialects``, or
another package) declares :class:`StandIns` through the entry-point group ``aeroexec.mission_imports``: the names it
serves and the module serving each, the import finders a running mission needs (ROS modules a mission imports and
never uses), the imports judged by their use rather than by being found, the names that make a program without
``mission()`` a script run whole, and the environment such a script is run in. The core imports no dialect.

aeroexec installs nothing under those names: an environment with ROS 2 keeps its own ``rclpy``, and a program that
embeds aeroexec imports what it would without it. A mission aeroexec loads imports through :func:`mission_import`:
an import of one of the served names (or of a module in it) gets the serving module, whatever else the
environment holds, since a mission aeroexec flies talks to its engine, not to a ROS graph. Nothing is put in
``sys.modules`` under those names: only the mission's own code sees them.
"""

from __future__ import annotations

import ast
import builtins
import functools
import logging
import sys
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from aeroexec.plugins import installed_plugins, load_reference

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

#: The entry-point group dialects declare their stand-ins through.
ENTRY_POINT_GROUP = "aeroexec.mission_imports"


@dataclass(frozen=True)
class StandIns:
    """What a dialect serves to the missions aeroexec loads. References are ``module:attribute``.

    ``names``: top-level import name -> the module serving it (``"rclpy": "aeroexec.dialects.aerostack2.rclpy"``).
    ``finders``: import finders (``importlib.abc.MetaPathFinder`` objects) put last on ``sys.meta_path`` while
    missions run. ``judged_by_use``: ``(module) -> bool``, True for an import the static check does not require
    to be found (its uses are judged instead). ``scripts``: names whose import makes a program without
    ``mission()`` a script, run whole. ``environment``: variables a script is run with when not set already.
    ``drones``: ``(tree: ast.Module) -> tuple[str, ...]``, the drones a script flies by the names it gives them
    (Aerostack2's namespaces, from its code or its argparse defaults); several make ``aeroexec run`` fly a fleet.
    ``unjournaled``: name -> the API's title, for names whose missions cannot be resumed: what they run through
    that API (Aerostack2's behavior runs) is not a journaled call of the mission API, so a resume could not replay it.
    """

    names: Mapping[str, str] = field(default_factory=dict)
    finders: tuple[str, ...] = ()
    judged_by_use: str | None = None
    scripts: tuple[str, ...] = ()
    environment: Mapping[str, str] = field(default_factory=dict)
    drones: str | None = None
    unjournaled: Mapping[str, str] = field(default_factory=dict)


@functools.cache
def declared() -> tuple[StandIns, ...]:
    """The stand-ins of the installed ``aeroexec.mission_imports`` entry points."""
    found = []
    for origin, provided in installed_plugins(ENTRY_POINT_GROUP):
        if isinstance(provided, StandIns):
            found.append(provided)
        else:
            logger.error("%s is not a StandIns: %r", origin, provided)
    return tuple(found)


@functools.cache
def served() -> dict[str, str]:
    """Every top-level name a mission's import is served by aeroexec -> the module serving it."""
    return {name: module for stand_ins in declared() for name, module in stand_ins.names.items()}


def stands_in(module: str) -> bool:
    """True when aeroexec serves ``module`` (``rclpy``, ``as2_python_api.drone_interface``...) to its missions."""
    return module.partition(".")[0] in served()


def judged_by_use(module: str) -> bool:
    """True when a dialect judges an import of ``module`` by what the mission uses of it (a ROS module)."""
    return any(s.judged_by_use is not None and load_reference(s.judged_by_use)(module) for s in declared())


def script_names() -> frozenset[str]:
    """The modules whose import makes a program without ``mission()`` a script, run whole."""
    return frozenset(name for s in declared() for name in s.scripts)


def unjournaled(module: str) -> str | None:
    """The title of the API ``module`` belongs to when a mission importing it cannot be resumed
    (:attr:`StandIns.unjournaled`), else None."""
    name = module.partition(".")[0]
    return next((s.unjournaled[name] for s in declared() if name in s.unjournaled), None)


def script_environment() -> dict[str, str]:
    """The environment variables a script is run with (when not set already)."""
    return {key: value for s in declared() for key, value in s.environment.items()}


def script_drones(tree: ast.Module) -> tuple[str, ...]:
    """The drones the script ``tree`` flies, by the names it gives them, each once (empty: one drone, unnamed)."""
    found: dict[str, None] = {}
    for reference in (s.drones for s in declared() if s.drones is not None):
        found.update(dict.fromkeys(load_reference(reference)(tree)))
    return tuple(found)


_lock = threading.Lock()


def install_finders() -> None:
    """Put the dialects' import finders last on ``sys.meta_path`` (idempotent)."""
    with _lock:
        for reference in (r for s in declared() for r in s.finders):
            finder = load_reference(reference)
            if finder not in sys.meta_path:
                sys.meta_path.append(finder)


def mission_import(real_import: Callable[..., Any] | None = None) -> Callable[..., Any]:
    """``__import__`` as a mission sees it: the served names and their modules are aeroexec's, every other import
    is ``real_import``'s (``builtins.__import__`` when None)."""
    real_import = real_import or builtins.__import__
    serving = served()

    def import_(name: str, globals: Any = None, locals: Any = None, fromlist: Any = (), level: int = 0) -> Any:
        top, dot, rest = name.partition(".")
        if level or top not in serving:
            return real_import(name, globals, locals, fromlist, level)
        package = serving[top]
        try:
            module = real_import(f"{package}{dot}{rest}", None, None, fromlist, 0)
        except ModuleNotFoundError as missing:  # in the mission's words: No module named 'executive_engine_api.x'
            raise ModuleNotFoundError(str(missing).replace(package, top), name=name) from None
        return module if fromlist else sys.modules[package]

    return import_


def mission_builtins() -> dict[str, Any]:
    """The builtins of a mission's module: :func:`mission_import` as its ``__import__``."""
    return {**vars(builtins), "__import__": mission_import()}


__all__ = ["ENTRY_POINT_GROUP", "StandIns", "declared", "install_finders", "judged_by_use", "mission_builtins",
           "mission_import", "script_drones", "script_environment", "script_names", "served", "stands_in",
           "unjournaled"]
