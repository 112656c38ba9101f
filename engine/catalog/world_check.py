"""A request's literal destinations and paths checked against a world before flight: inside its bounds (the
geofence), and as far from its obstacles as the behavior's catalog preconditions ask
(``minimum_distance_to_obstacle(?DESTINATION, ?d), ?d > 3``), naming the obstacle and the distance.

The arguments checked are the absolute positions a behavior flies to: ``COORDINATES`` and ``DESTINATION``
(one point) and ``PATH`` (a list of points). A precondition on ``?DESTINATION`` is the point of
``COORDINATES`` (GO_TO_POINT binds it so); relative coordinates depend on where the drone will be and are
checked in flight.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence

from aeroexec.engine.catalog.descriptors import BehaviorDescriptor

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, Protocol
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

POINT_ARGUMENTS = ("COORDINATES", "DESTINATION")
LOOKED_AT = ("LOOK_AT_A_POINT",)  # behaviors whose COORDINATES are looked at, not flown to: never checked
PATH_ARGUMENTS = ("PATH",)
_CLEARANCE = re.compile(r"minimum_distance_to_obstacle\(\s*\?(\w+)\s*,\s*\?(\w+)\s*\)")


class WorldMap(Protocol):
    """What verification needs of a world (the simulated world has it): bounds and named obstacles."""

    bounds: Any  # .lower, .upper: ENU corners
    obstacles: Sequence[Any]  # each with .name and .signed_distance(point)

    def inside(self, point: tuple[float, float, float]) -> bool: ...


def clearance(descriptor: BehaviorDescriptor) -> tuple[str, float, bool] | None:
    """``(variable, meters, strict)`` when the preconditions ask a point to be that far from every obstacle."""
    text = descriptor.precondition_text
    for match in _CLEARANCE.finditer(text):
        point, distance = match.groups()
        bound = re.search(rf"\?{distance}\s*(>=|>)\s*(-?[\d.]+)", text)
        if bound:
            return point, float(bound.group(2)), bound.group(1) == ">"
    return None


def nearest_obstacle(world: WorldMap, point: Sequence[float]) -> tuple[str, float] | None:
    """The name of the obstacle nearest to ``point`` and the distance to its surface (0 inside it)."""
    best = None
    for obstacle in world.obstacles:
        distance = max(float(obstacle.signed_distance(tuple(point))), 0.0)
        if best is None or distance < best[1]:
            best = (str(getattr(obstacle, "name", "an obstacle")), distance)
    return best


def clearance_note(descriptor: BehaviorDescriptor, bindings: Mapping[str, Any], world: Any) -> str:
    """In flight, why a clearance precondition fails, naming the obstacle: ``(5, 5, 3) is 2.1 m from tower;
    GO_TO_POINT needs 3 m`` ("" when there is no such precondition, no named obstacles, or it holds)."""
    rule = clearance(descriptor)
    if rule is None or not getattr(world, "obstacles", None):
        return ""
    variable, meters, strict = rule
    point = _point(bindings.get(f"?{variable}"))
    nearest = nearest_obstacle(world, point) if point is not None else None
    if nearest is None or (nearest[1] > meters if strict else nearest[1] >= meters):
        return ""
    return f"{_fmt(point)} is {nearest[1]:.1f} m from {nearest[0]}; {descriptor.name} needs {meters:g} m"


def _point(value: Any) -> tuple[float, float, float] | None:
    if isinstance(value, Sequence) and not isinstance(value, str) and len(value) == 3 and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value):
        return (float(value[0]), float(value[1]), float(value[2]))
    return None


def _fmt(point: Sequence[float]) -> str:
    return "(" + ", ".join(f"{round(v, 2):g}" for v in point) + ")"


def _bounds(world: WorldMap) -> str:
    lower, upper = world.bounds.lower, world.bounds.upper
    return ", ".join(f"{axis} {lo:g}..{hi:g}" for axis, lo, hi in zip("xyz", lower, upper, strict=True))


def world_problems(descriptor: BehaviorDescriptor, arguments: Mapping[str, Any],
                   world: WorldMap) -> list[tuple[str, str]]:
    """``(argument, why)`` for each literal point the world refuses: outside the bounds, or too near an obstacle."""
    name = descriptor.name
    problems = []
    points: list[tuple[str, tuple[float, float, float]]] = []
    if name in LOOKED_AT:
        return problems
    for key in POINT_ARGUMENTS:
        if (point := _point(arguments.get(key))) is not None:
            points.append((key, point))
    for key in PATH_ARGUMENTS:
        value = arguments.get(key)
        if isinstance(value, Iterable) and not isinstance(value, str | Mapping):
            points += [(key, p) for p in (_point(v) for v in value) if p is not None]
    for key, point in points:
        if not world.inside(point):
            why = getattr(world, "why_outside", None)
            problems.append((key, f"{_fmt(point)} is " + (why(point) if why is not None else
                                                          f"outside the world's bounds ({_bounds(world)}; geofence)")))
    rule = clearance(descriptor)
    if rule is not None:
        variable, meters, strict = rule
        argument = "COORDINATES" if variable == "DESTINATION" and "DESTINATION" not in arguments else variable
        for key, point in points:
            if key != argument or not world.inside(point):
                continue
            nearest = nearest_obstacle(world, point)
            if nearest is not None and (nearest[1] <= meters if strict else nearest[1] < meters):
                problems.append((key, f"{_fmt(point)} is {nearest[1]:.1f} m from {nearest[0]}; {name} needs "
                                      f"{meters:g} m"))
    return problems


__all__ = ["WorldMap", "clearance", "clearance_note", "nearest_obstacle", "world_problems"]
