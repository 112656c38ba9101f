"""Reading and checking a mission file of any format of the table (``trees/formats.py``): a Python program, a
behavior tree (BehaviorTree.CPP XML, YAML, Aerostack's ``nodes:``), a TML mission or a QGroundControl plan.

``check_mission(path, catalog)`` returns what would fly (the mission function or the tree document) and every
problem found before flight, each naming the file and line; ``load_mission`` is what a flight flies, or the
refusal.
"""

from __future__ import annotations

import importlib.util
import math
import sys
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.drones.geodesy import Geodetic
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.errors import Problem
from aeroexec.engine.robots import robot_kind_hint
from aeroexec.flight.errors import FlightError
from aeroexec.trees.formats import TREE_VERIFIERS, described, format_of, readers, suffixes

from aeroexec.limits import InputError, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.trees import TreeDocument
    from aeroexec.trees.route import RouteEstimate


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
    """A mission of a tree format of the table (trees/formats.py): behavior trees, TML, mission items."""
    fmt = format_of(path)
    return fmt is not None and fmt.tree


def check_mission(path: Path, catalog: BehaviorCatalog, world: Any = None, home: Geodetic | None = None,
                  vehicle: Any = None) -> CheckedMission:
    """Read and check a mission without flying it (against ``world``'s bounds and obstacles when given);
    raises :class:`MissionFileError` when it cannot be read. ``home`` places a QGroundControl plan and GPS points
    of Aerostack2's missions (default: ``world``'s home, else the default simulated world's). ``vehicle``: the
    :class:`~aeroexec.drones.sim.SimConfig` the route is costed with (a ``--vehicle`` profile's; default: the
    simulated multicopter's)."""
    fmt = format_of(path)
    if home is None and world is not None and fmt is not None and fmt.tree:  # plans, Aerostack2's GPS nodes
        home = world.home
    if path.is_dir():
        inside = sorted(p.name for p in path.iterdir()
                        if p.name.lower().endswith(suffixes()) and not p.name.startswith(("_", ".")))
        some = f" (missions in it: {', '.join(inside[:4])}{', ...' if len(inside) > 4 else ''})" if inside else ""
        raise MissionFileError(f"{path}: it is a directory, not a mission file: give the mission's file{some}")
    checked = CheckedMission(path)
    if fmt is None:
        what = "no such file" if not path.exists() else "not a mission file"
        raise MissionFileError(f"{path}: {what}: a mission is a Python program or a behavior tree, in one of the "
                               f"formats {described()}")
    if fmt.tree:
        # here, not at the top: a Python mission needs none of tree verification (its checks, the format readers)
        # nor the tree model
        from aeroexec.trees import TreeFormatError, load_mission_tree
        from aeroexec.trees.route import estimate_route
        from aeroexec.trees.verify import verify_document, verify_leaves

        try:
            checked.tree = load_mission_tree(path, home)
        except TreeFormatError as error:
            checked.problems = [Problem("error", message, file, line) for file, line, message in error.problems]
            checked.problems += verify_leaves(error.leaves, catalog, str(path))  # the catalog's word as well
            checked.problems.sort(key=lambda p: (p.file, p.line))
            return checked
        plan = fmt.items  # read as a PlanDocument: its items, numbered
        if plan and not checked.tree.root.children:
            checked.problems = list(checked.tree.problems)  # no item flies: the items' problems say why
            return checked
        own = (found for _, verify in sorted(readers(TREE_VERIFIERS).items())  # a dialect's: a TML mission's
               if (found := verify(checked.tree, catalog, world)) is not None)
        problems = next(own, None)
        checked.problems = problems if problems is not None else verify_document(checked.tree, catalog, world=world)
        checked.route = estimate_route(checked.tree, world, vehicle, catalog=catalog) if world is not None else None
        if checked.route is not None:
            checked.problems += checked.route.problems
        if vehicle is not None and not getattr(vehicle, "camera", True):
            checked.problems += no_camera(checked.tree, str(path))
        if plan:  # items without a behavior, each message with its item number
            checked.problems = checked.tree.numbered([*checked.tree.problems, *checked.problems])
        checked.problems.sort(key=lambda p: (p.file, p.line))
        return checked
    try:
        checked.source = read_text(path, what="the mission")
    except InputError as exc:
        raise MissionFileError(str(exc)) from None
    # the format's check, imported here: a tree mission needs none of the Python mission's checks
    checked.problems = fmt.reader()(checked.source, str(path), catalog, world)
    return checked



def is_tree_document(mission: object) -> bool:
    """Whether ``mission`` (what :func:`load_mission` returns) is a tree document, not a Python mission's function:
    asked without importing the tree model, which a flight of a Python mission never needs (no document exists
    before it is imported)."""
    model = sys.modules.get("aeroexec.trees.model")
    return model is not None and isinstance(mission, model.TreeDocument)


def photo_behaviors(document: TreeDocument) -> list[Any]:
    """A tree's photo behaviors (TAKE_PHOTO, TRIGGER_CAMERA), in order."""
    found, stack = [], [document.root]
    while stack:
        node = stack.pop()
        if node.type in ("TAKE_PHOTO", "TRIGGER_CAMERA"):
            found.append(node)
        stack.extend(reversed(node.children))
    return found


def no_camera(document: TreeDocument, file: str) -> list[Problem]:
    """The warning for a vehicle without a camera and a tree that takes photos (none when it takes none)."""
    photos = photo_behaviors(document)
    if not photos:
        return []
    count = len(photos)
    return [Problem("warning", f"the vehicle has no camera: the mission's {count} photo behavior"
                               f"{'s' if count != 1 else ''} (TAKE_PHOTO, TRIGGER_CAMERA) skip their photos, said in "
                               f"the event log (photo_skipped), and the mission goes on",
                    photos[0].file or file, photos[0].line)]


def load_mission(path: Path, catalog: BehaviorCatalog, world: Any = None,
                 report: Callable[[Problem], None] = lambda problem: None, verb: str = "fly",
                 vehicle: Any = None, max_time: float | None = None,
                 script_args: tuple[str, ...] = ()) -> Callable[[], Any] | TreeDocument:
    """Check a mission before flight (against ``world`` when given), each problem to ``report``; the Python
    function or the tree to fly. Raises :class:`MissionFileError` when it has errors. ``verb``: what the robot
    does (a rover does not fly); a route longer than ``max_time`` (the run's time limit) is a warning;
    ``script_args``: a script's own arguments (its ``sys.argv[1:]``)."""
    checked = check_mission(path, catalog, world, vehicle=vehicle)
    route = checked.route
    if route is not None and max_time is not None and route.duration > max_time and not route.forever:
        checked.problems.append(Problem(
            "warning", f"the route takes about {route.duration / 60:.0f} min, longer than the run's time limit "
                       f"of {max_time:g} s: the run stops there; give --max-time {60 * math.ceil(route.duration / 50)}",
            str(path), 0))
    for problem in checked.problems:
        report(problem)
    if hint := robot_kind_hint(p.message for p in checked.problems):  # a rover's mission without --robot rover
        report(Problem("hint", hint, str(path), 0))
    if checked.errors:
        count = len(checked.errors)
        raise MissionFileError(f"{path}: {count} error{'s' if count != 1 else ''}; the mission will not {verb}")
    return checked.tree if checked.tree is not None else mission_function(path, script_args)


def script_drones(mission: Path) -> tuple[str, ...]:
    """The drones the Python script ``mission`` flies, by the names it gives them; empty for a mission that is not
    such a script (or that cannot be read: its check says why). A run asks it of every mission it flies on the
    simulator (``aeroexec run``: a script of several drones is flown as a fleet, :mod:`.fleet.script_fleet`)."""
    from aeroexec.engine.missions import standins
    from aeroexec.engine.missions.script import is_script
    from aeroexec.engine.missions.source import parse_source

    if Path(mission).suffix != ".py":
        return ()
    try:
        tree = parse_source(Path(mission).read_text(encoding="utf-8"), str(mission))  # (the check's parse, kept)
    except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return ()
    return standins.script_drones(tree) if is_script(tree) else ()


def mission_function(path: Path, script_args: tuple[str, ...] = ()) -> Callable[[], Any]:
    """Import a checked Python mission and return its ``mission()`` or ``runMission()`` function (an Aerostack2
    script, which has none, is run whole, with ``script_args`` as its arguments:
    :mod:`aeroexec.engine.missions.script`)."""
    from aeroexec.engine.missions import standins
    from aeroexec.engine.missions.script import is_script, script_mission
    from aeroexec.engine.missions.source import parse_source

    source = read_text(path, what="the mission")
    if is_script(parse_source(source, str(path))):
        return script_mission(path, source, script_args)
    standins.install_finders()  # a ROS module the mission imports and never uses imports as a stand-in
    spec = importlib.util.spec_from_file_location(f"aeroexec_mission_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    module.__builtins__ = standins.mission_builtins()  # its imports of Aerostack's APIs get aeroexec's
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


def safety_check(checked: CheckedMission, catalog: BehaviorCatalog, rules_files: Iterable[str] = (),
                 model: VehicleModel | None = None) -> tuple[BehaviorCatalog, list[Problem]]:
    """The catalog with the safety rules of the mission and of ``rules_files`` added, and the problems of those
    rules: their own (syntax, unknown predicates or contingencies, with file:line) and, when they are sound, the
    mission's literal destinations that break one (engine/safety/static.py)."""
    from aeroexec.engine.safety.declared import mission_rules, rules_file
    from aeroexec.engine.safety.static import route, route_problems

    found = mission_rules(checked.path, catalog)
    for name in rules_files:
        found.extend(rules_file(name, catalog))
    problems = list(found.problems)
    if found.errors:
        return catalog, problems
    watched = catalog.with_safety_rules(found.rules)
    mission = _requests(checked, watched)
    if watched.safety_rules and mission is not None and not checked.errors:
        model = model or VehicleModel()
        problems += route_problems(route(mission, str(checked.path), model, watched), watched.safety_rules, model)
    return watched, problems


def _requests(checked: CheckedMission, catalog: BehaviorCatalog) -> Any:
    """What the safety rules' route is read from: a tree, or a program's requests in the order written (every
    way it names a destination: any case, an alias, a drone interface's positional arguments); None without."""
    if checked.tree is not None:
        return checked.tree
    if checked.source is None:
        return None
    from aeroexec.engine.missions.check import literal_requests

    return literal_requests(checked.source, str(checked.path), catalog)


def fleet_safety_check(path: Path, catalog: BehaviorCatalog, rules_files: Iterable[str] = (),
                       world: Any = None) -> list[Problem] | None:
    """A fleet file's routes flown together against the separation rules of its missions and ``rules_files``
    (engine/safety/static.py); None when ``path`` is not a fleet file."""
    from dataclasses import replace

    try:
        text = read_text(path, what="the mission")
    except InputError:
        return None
    if path.suffix.lower() not in (".yaml", ".yml") or "\ndrones:" not in "\n" + text:
        return None
    from aeroexec.engine.safety.static import Waypoint, route, separation_problems
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet  # a fleet file: the fleet extra is needed
    try:
        fleet = load_fleet(path)
    except FleetFileError as error:
        return [Problem("error", str(error), str(path), 0)]
    routes, rules, problems = {}, [], []
    for drone in fleet.drones:
        checked = check_mission(drone.mission, catalog, world)
        watched, found = safety_check(checked, catalog, rules_files)
        problems += found
        rules += [r for r in watched.safety_rules if r not in rules]
        model = replace(VehicleModel(), home=(drone.home[0], drone.home[1], 0.0))
        mission = _requests(checked, watched)
        start = Waypoint(model.home, str(drone.mission), 0)  # where it stands at first
        routes[drone.name] = [start, *(route(mission, str(drone.mission), model, watched)
                                       if mission is not None else [])]
    return problems + separation_problems(routes, rules, VehicleModel())


def watched_catalog(path: Path, catalog: BehaviorCatalog, rules_files: Iterable[str] = (), world: Any = None,
                    report: Callable[[Problem], None] = lambda problem: None, vehicle: Any = None
                    ) -> BehaviorCatalog:
    """The catalog a flight watches the safety rules of (:func:`safety_check`); raises :class:`MissionFileError`
    when a rule is wrong or the mission breaks one before flight."""
    from aeroexec.engine.safety.declared import mission_rules

    declared = mission_rules(path, catalog)
    if not (rules_files or catalog.safety_rules or declared.rules or declared.problems):
        return catalog  # no rules: nothing to check again
    checked = check_mission(path, catalog, world, vehicle=vehicle)
    watched, problems = safety_check(checked, catalog, rules_files,
                                     VehicleModel(vehicle) if vehicle is not None else None)
    for problem in problems:
        report(problem)
    errors = [p for p in problems if p.severity == "error"]
    if errors:
        raise MissionFileError(f"{path}: {len(errors)} safety rule error{'s' if len(errors) != 1 else ''}; "
                               f"the mission will not fly")
    return watched


def world_home(world: str | None) -> Geodetic:
    """The home point of the simulated world in ``world`` (a file; None: the built-in world)."""
    from aeroexec.drones.sim import WorldError, default_world, load_world

    try:
        return (load_world(world) if world else default_world()).home
    except WorldError as error:
        raise MissionFileError(str(error)) from None
