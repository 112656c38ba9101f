"""Safety rules decided before flight, where the mission alone decides them: its literal destinations (a tree's
``GO_TO_POINT COORDINATES="..."``, a Python mission's requests however it writes them: ``coordinates=``,
``point=``, any case, Aerostack2's ``go_to(x, y, z)``, as :func:`aeroexec.engine.missions.check.literal_requests`
reads them) in the order written, flown from home with the vehicle model's battery use (the model verify's route
uses). What a request flies to is read through the catalog's argument descriptors: its place arguments
(``allowed_values: WORLD``) that are destinations or paths, relative coordinates from the point before, a
take-off's altitude.

A rule is decided at each destination when what it reads is known there: ``position(self, P)`` (the destination),
``charge(battery, C)`` (100 % at take-off less the route's use so far), the geometry (``distance``), the return
estimates (``battery_to_home``, ``return_margin``) and the built-ins. A ``never`` condition that holds there, or an
``always`` condition that fails, is an error at the destination's file:line naming the rule. Fleet routes are
checked pairwise against separation rules (``position(?other, Q)`` of another drone) on one timeline.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from aeroexec.beliefs import Struct
from aeroexec.beliefs.expression import BUILTIN_PREDICATES
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.catalog import BehaviorCatalog, default_catalog
from aeroexec.engine.catalog.descriptors import DELIBERATIVE
from aeroexec.engine.catalog.safety_rules import ALWAYS, NEVER, SafetyRule
from aeroexec.engine.catalog.world_check import LOOKED_AT, PATH_ARGUMENTS, POINT_ARGUMENTS
from aeroexec.engine.errors import Problem
from aeroexec.engine.safety.predicates import SafetyPredicates

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.beliefs import BeliefMemory

KNOWN = {("position", 2), ("charge", 2), ("distance", 3), ("battery_to_home", 2), ("return_margin", 2),
         ("rally_distance", 2), ("stopping_point", 2)} | BUILTIN_PREDICATES  # at a destination, at rest


@dataclass(frozen=True)
class Waypoint:
    """A literal destination of the mission, where it is written, and what flying there from the last one takes."""

    point: tuple[float, float, float]
    file: str
    line: int
    seconds: float = 0.0  # since take-off, arriving
    charge: float = 100.0  # percent left, arriving


def decidable(rule: SafetyRule, fleet: bool = False) -> bool:
    """Whether the rule reads only what a route says (and, for ``fleet``, other drones' positions)."""
    if rule.form not in (ALWAYS, NEVER):
        return False
    return rule.predicates <= KNOWN and (not fleet or _mentions_others(rule))


def _mentions_others(rule: SafetyRule) -> bool:
    return bool(re.search(r"position\(\s*\?", rule.condition.text))


def route(mission: Any, file: str, model: VehicleModel, catalog: BehaviorCatalog | None = None) -> list[Waypoint]:
    """The literal destinations of a mission in order, with time and charge: ``mission`` is a tree document, or a
    program's requests in the order written (``(behavior, arguments, line)``, as
    :func:`aeroexec.engine.missions.check.literal_requests` reads them). What a request flies to is read through
    the ``catalog``'s argument descriptors (default: the aerial catalog): its names and aliases in any case."""
    catalog = catalog or default_catalog()
    requests = _tree_requests(mission) if hasattr(mission, "trees") else [
        (behavior, arguments, file, line) for behavior, arguments, line in mission]
    here, seconds, charge = model.home, 0.0, 100.0
    points = []
    for behavior, arguments, where, line in requests:
        for point in _destinations(catalog, behavior, arguments, here):
            if point is None:
                continue
            if len(point) == 1:  # a climb (TAKE_OFF): the altitude above where it is
                point = (here[0], here[1], point[0])
                leg_seconds, used = model.take_off(point[2] - here[2])
            else:
                leg_seconds, used = model.fly(here, point)
            seconds, charge, here = seconds + leg_seconds, charge - used, point
            points.append(Waypoint(point, where, line, round(seconds, 2), round(charge, 2)))
    return points


def _destinations(catalog: BehaviorCatalog, behavior: str, given: Mapping[str, Any],
                  here: tuple[float, float, float]) -> list[tuple[float, ...] | None]:
    """Where a request flies, in order: the points of its place arguments a behavior flies to (the catalog's
    ``allowed_values: WORLD`` arguments that are destinations or paths, not points looked at), a relative
    destination from ``here``, a take-off's altitude (one number); None for a destination known only in flight."""
    descriptor = catalog.behavior(str(behavior).upper())
    if descriptor is None or descriptor.category == DELIBERATIVE or descriptor.name in LOOKED_AT:
        return []
    known = {alias.upper(): a.name for a in descriptor.arguments.values() for alias in (a.name, *a.aliases)}
    arguments = {known.get(str(k).upper(), str(k).upper()): v for k, v in given.items()}
    if catalog.motion_of(descriptor.name) == "climb":  # a take-off (the catalog's motion: climb)
        return [_numbers(arguments["ALTITUDE"])] if "ALTITUDE" in arguments else []
    found: list[tuple[float, ...] | None] = []
    for name, value in arguments.items():
        argument = descriptor.arguments.get(name)
        if argument is None or not argument.is_place:
            continue
        if name in PATH_ARGUMENTS or argument.value_type == "PATH":
            if name in PATH_ARGUMENTS:
                points = value if isinstance(value, list | tuple) and not _numbers(value) else [value]
                found += [_point(v) for v in points]
        elif name in POINT_ARGUMENTS:
            found.append(_point(value))
    if "RELATIVE_COORDINATES" in arguments and "RELATIVE_COORDINATES" in descriptor.arguments:
        delta = _point(arguments["RELATIVE_COORDINATES"])
        found.append(None if delta is None else tuple(h + d for h, d in zip(here, delta, strict=True)))
    return found


def _point(value: Any) -> tuple[float, ...] | None:
    numbers = _numbers(value)
    return numbers if numbers is not None and len(numbers) == 3 else None


def route_problems(points: Iterable[Waypoint], rules: Iterable[SafetyRule], model: VehicleModel) -> list[Problem]:
    """An error for each destination where a decidable rule is broken, and why."""
    problems = []
    rules = [rule for rule in rules if decidable(rule) and not _mentions_others(rule)]
    if not rules:
        return []
    for waypoint in points:
        memory = _scratch(model, waypoint.point, waypoint.charge)
        for rule in rules:
            found = memory.query(rule.condition)
            broken = found is None if rule.form == ALWAYS else found is not None
            if broken:
                where = f"{_fmt(waypoint.point)} (about {waypoint.charge:.0f} % left on arrival)"
                problems.append(Problem("error", f"the destination {where} breaks safety rule {rule.name} "
                                                 f"({rule.where}): {rule.text}", waypoint.file, waypoint.line))
    return problems


def separation_problems(routes: dict[str, list[Waypoint]], rules: Iterable[SafetyRule], model: VehicleModel,
                        step: float = 0.5) -> list[Problem]:
    """An error for each pair of fleet routes that come closer than a separation rule allows, flown together
    from the start at cruise speed (at the first place and time they do)."""
    rules = [rule for rule in rules if decidable(rule, fleet=True)]
    names = sorted(routes)
    problems = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            end = max([w.seconds for w in routes[a] + routes[b]] or [0.0])
            t = 0.0
            while t <= end + step:
                pa, pb = _at(routes[a], t, model), _at(routes[b], t, model)
                memory = _scratch(model, pa, 100.0)
                memory.add(Struct("position", (b, pb)))
                broken = [r for r in rules if (memory.query(r.condition) is None) == (r.form == ALWAYS)]
                if broken:
                    rule = broken[0]
                    leg = next((w for w in routes[a] if w.seconds >= t), routes[a][-1] if routes[a] else None)
                    problems.append(Problem(
                        "error", f"the routes of {a} and {b} come {math.dist(pa, pb):.1f} m apart at t={t:.1f} s "
                                 f"near {_fmt(pa)}: safety rule {rule.name} ({rule.where}): {rule.text}",
                        leg.file if leg else "", leg.line if leg else 0))
                    break
                t += step
    return problems


def _at(points: list[Waypoint], t: float, model: VehicleModel) -> tuple[float, float, float]:
    here, since = (points[0].point, 0.0) if points and points[0].seconds == 0.0 else (model.home, 0.0)
    for w in points:
        if t <= w.seconds:
            span = w.seconds - since
            f = 1.0 if span <= 0 else (t - since) / span
            return tuple(h + (p - h) * f for h, p in zip(here, w.point, strict=True))  # type: ignore[return-value]
        here, since = w.point, w.seconds
    return here


def _scratch(model: VehicleModel, point: tuple, charge: float) -> BeliefMemory:
    from aeroexec.beliefs import BeliefMemory  # here: a mission checked against no decidable rule needs none

    memory = BeliefMemory(clock=lambda: 0.0)
    memory.register("distance", 3, lambda a, b: round(math.dist(a, b), 2) if _is_point(a) and _is_point(b) else None)
    SafetyPredicates(memory, model, lambda: 0.0).register()
    memory.add(Struct("position", ("self", tuple(round(v, 2) for v in point))))
    memory.add(Struct("charge", ("battery", int(math.floor(charge)))))
    return memory


def _is_point(value: Any) -> bool:
    return isinstance(value, tuple) and len(value) == 3 and all(isinstance(v, int | float) for v in value)


def _numbers(value: Any) -> tuple[float, ...] | None:
    if isinstance(value, str):
        text = value.strip().strip("[]()")
        try:
            value = [float(part) for part in re.split(r"[,;\s]+", text) if part]
        except ValueError:
            return None
    if isinstance(value, int | float) and not isinstance(value, bool):
        return (float(value),)
    if isinstance(value, list | tuple) and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        return tuple(float(v) for v in value) if len(value) in (1, 3) else None
    return None


def _tree_requests(document: Any) -> list[tuple[str, dict[str, Any], str, int]]:
    """A tree's behavior leaves in the order written (through its SubTrees), with their literal ports: a port
    read from the blackboard (``{key}``) is known only in flight."""
    found: list[tuple[str, dict[str, Any], str, int]] = []

    def visit(tree_id: str, depth: int) -> None:
        root = document.trees.get(tree_id)
        if root is None or depth > 16:
            return
        for node in root.walk():
            if node.type == "SubTree" and node.ports.get("ID"):
                visit(node.ports["ID"], depth + 1)
                continue
            ports = {k: (None if isinstance(v, str) and "{" in v else v) for k, v in node.ports.items()}
            found.append((node.type, ports, node.file, node.line))

    visit(document.main, 0)
    return found


def _fmt(point: Iterable[float]) -> str:
    return "(" + ", ".join(f"{v:g}" for v in (round(p, 1) for p in point)) + ")"


__all__ = ["Waypoint", "decidable", "route", "route_problems", "separation_problems"]
