"""Reading and checking a mission file of any kind: a Python program, a behavior tree (BehaviorTree.CPP XML,
YAML, Aerostack's ``nodes:``), a TML mission or a QGroundControl plan.

``check_mission(path, catalog)`` returns what would fly (the mission function or the tree document) and every
problem found before flight, each naming the file and line; ``load_mission`` is what a flight flies, or the
refusal.
"""

from __future__ import annotations

import importlib.util
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.drones.geodesy import Geodetic
from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.errors import Problem
from aeroexec.engine.missions.check import check_mission_source
from aeroexec.flight.spec import FlightError
from aeroexec.trees import MISSION_EXTENSIONS, TreeDocument, TreeFormatError, load_mission_tree
from aeroexec.trees.items import PlanDocument, is_item_file
from aeroexec.trees.route import RouteEstimate, estimate_route
from aeroexec.trees.tml.verify import verify_mission_document
from aeroexec.trees.verify import verify_leaves

from aeroexec.limits import InputError, read_text


class MissionFileError(FlightError):
    """A mission that cannot be flown, already phrased for the operator."""


@dataclass
class CheckedMission:
    """A mission file after its checks: ``tree`` for a behavior tree, ``source`` for a Python program."""

    path: Path
    problems: list[Problem] = field(default_factory=list)
    tree: TreeDocument | None = None
    source: str | None = None
    route: RouteEstimate | None = None  # a tree's route in the world: length, duration, battery at landing

    @property
    def errors(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "error"]


def is_tree(path: Path) -> bool:
    return path.suffix.lower() in MISSION_EXTENSIONS


def is_plan(path: Path) -> bool:
    """A mission-item file (QGroundControl plan or .mission, waypoint file), placed from a world's home."""
    return is_item_file(path)


def check_mission(path: Path, catalog: BehaviorCatalog, world: Any = None, home: Geodetic | None = None
                  ) -> CheckedMission:
    """Read and check a mission without flying it (against ``world``'s bounds and obstacles when given);
    raises :class:`MissionFileError` when it cannot be read. ``home`` places a QGroundControl plan (default:
    ``world``'s home, else the default simulated world's)."""
    if home is None and world is not None and is_plan(path):
        home = world.home
    checked = CheckedMission(path)
    if is_tree(path):
        try:
            checked.tree = load_mission_tree(path, home)
        except TreeFormatError as error:
            checked.problems = [Problem("error", message, file, line) for file, line, message in error.problems]
            checked.problems += verify_leaves(error.leaves, catalog, str(path))  # the catalog's word as well
            checked.problems.sort(key=lambda p: (p.file, p.line))
            return checked
        if isinstance(checked.tree, PlanDocument) and not checked.tree.root.children:
            checked.problems = list(checked.tree.problems)  # no item flies: the items' problems say why
            return checked
        checked.problems = verify_mission_document(checked.tree, catalog, world)  # TML missions too
        checked.route = estimate_route(checked.tree, world) if world is not None else None
        if checked.route is not None:
            checked.problems += checked.route.problems
        if isinstance(checked.tree, PlanDocument):  # items without a behavior, each message with its item number
            checked.problems = checked.tree.numbered([*checked.tree.problems, *checked.problems])
        checked.problems.sort(key=lambda p: (p.file, p.line))
        return checked
    if path.suffix.lower() != ".py":
        raise MissionFileError(f"{path}: a mission is a Python program (.py) or a behavior tree "
                               f"({', '.join(sorted(MISSION_EXTENSIONS))})")
    try:
        checked.source = read_text(path, what="the mission")
    except InputError as exc:
        raise MissionFileError(str(exc)) from None
    checked.problems = check_mission_source(checked.source, str(path), catalog, world)
    return checked


def load_mission(path: Path, catalog: BehaviorCatalog, world: Any = None,
                 report: Callable[[Problem], None] = lambda problem: None) -> Callable[[], Any] | TreeDocument:
    """Check a mission before flight (against ``world`` when given), each problem to ``report``; the Python
    function or the tree to fly. Raises :class:`MissionFileError` when it has errors."""
    checked = check_mission(path, catalog, world)
    for problem in checked.problems:
        report(problem)
    if checked.errors:
        count = len(checked.errors)
        raise MissionFileError(f"{path}: {count} error{'s' if count != 1 else ''}; the mission will not fly")
    return checked.tree if checked.tree is not None else mission_function(path)


def mission_function(path: Path) -> Callable[[], Any]:
    """Import a checked Python mission and return its ``mission()`` or ``runMission()`` function."""
    spec = importlib.util.spec_from_file_location(f"aeroexec_mission_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    try:
        with warnings.catch_warnings():  # SyntaxWarnings of the mission's source are not the project's messages
            warnings.simplefilter("ignore", SyntaxWarning)
            warnings.simplefilter("ignore", DeprecationWarning)
            spec.loader.exec_module(module)
    except Exception as exc:
        raise MissionFileError(f"{path}: the mission cannot be loaded: {type(exc).__name__}: {exc}") from None
    function = getattr(module, "mission", None) or getattr(module, "runMission", None)
    if not callable(function):
        raise MissionFileError(f"{path}: no mission() or runMission() function")
    return function

