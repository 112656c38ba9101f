"""The whole route of a mission before flight: every leg against the world (bounds, geofence, obstacles), the
route's length, its duration at the planned speeds, and the battery left at landing from the vehicle's model.

A mission whose tree is a flight through known places (Sequences, Repeats, Parallels of behaviors that fly to
literal points, take off, land, wait, turn, take photos: every plan and waypoint file, most hand-written
sequences) has a route; others (fallbacks, conditions, points read from the blackboard) have none, and nothing
is said of them. The node kinds say how the route goes through them (``route``: ``trees.runtime.kinds``), the
catalog how each behavior moves and how long it takes (its ``motion``, ``duration`` and ``beside``). Each leg is
costed by the vehicle model (:class:`aeroexec.drones.vehicle.VehicleModel`, the one the safety rules' return
estimates use: the simulated multicopter's figures and its battery's drain). A route the
battery cannot finish above the failsafe threshold is an error at the item where the charge runs out, saying how
much is missing.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from aeroexec.drones.geodesy import geo_to_enu, is_geo, parse_geo
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.errors import WRONG_VALUE, MissionProblem
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.ports import parse_value
from aeroexec.trees.runtime.kinds import kind_of

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

Vector = tuple[float, float, float]
_ITEM = re.compile(r"item (\d+) ")
FENCE_STEP = 2.0  # m between the points of a leg checked against the geofence
RESERVE = 20.0  # %: landing with less than this is a warning


class NoRoute(Exception):
    """The tree is not a flight through known places."""


@dataclass
class RouteEstimate:
    """A mission's route: length (m), duration (s), battery at landing (%), and the problems found on the way."""

    length: float = 0.0
    duration: float = 0.0
    battery: float = 100.0
    failsafe: float = 0.0
    hover_minutes: float = 0.0
    problems: list[MissionProblem] = field(default_factory=list)
    forever: bool = False  # a Repeat forever (DO_JUMP -1): the figures are of one round of it

    def summary(self) -> str:
        minutes, seconds = divmod(round(self.duration), 60)
        patrol = "a patrol repeated forever, its first round: " if self.forever else ""
        return (f"{patrol}route {self.length / 1000:.2f} km, {minutes} min {seconds:02d} s at the planned speeds; "
                f"battery {max(self.battery, 0.0):.0f}% at landing (the vehicle's battery: {self.hover_minutes:g} "
                f"min of hover on a full charge)")


class _Flight:
    """Flies the tree on paper with the vehicle's model."""

    def __init__(self, document: TreeDocument, world: Any, config: Any, start: tuple[Vector, bool] | None = None,
                 catalog: Any = None) -> None:
        self.document, self.world, self.config, self.catalog = document, world, config, catalog
        self.model = VehicleModel(config)
        self.estimate = RouteEstimate(battery=config.initial_battery_percent,
                                      failsafe=config.failsafe_battery_percent,
                                      hover_minutes=config.battery_hover_minutes)
        self.position: Vector = start[0] if start is not None else (0.0, 0.0, 0.0)
        self.flying = start[1] if start is not None else False
        self.empty_at: TreeNode | None = None
        self.said: set[tuple[int, str]] = set()

    def problem(self, node: TreeNode, message: str, severity: str = "error") -> None:
        item = _ITEM.match(node.name)  # a mission item's behavior: its number (several items may share a line)
        message = f"item {item.group(1)}: {message}" if item else message
        if (node.line, message) not in self.said:
            self.said.add((node.line, message))
            self.estimate.problems.append(MissionProblem(severity, message, node.file or self.document.file,
                                                         node.line, WRONG_VALUE))

    # -- the vehicle's model ---------------------------------------------------------------------------------
    def spend(self, node: TreeNode, seconds: float, percent: float | None = None) -> None:
        """``seconds`` of the route, taking ``percent`` of the charge (default: hovering, or idle on the ground)."""
        self.estimate.duration += seconds
        self.estimate.battery -= self.model.hover(seconds, self.flying) if percent is None else percent
        if self.empty_at is None and self.estimate.battery < self.estimate.failsafe:
            self.empty_at = node

    def point(self, node: TreeNode, key: str) -> Vector:
        text = node.ports.get(key, "")
        if "{" in text:
            raise NoRoute(f"{node.type} reads {key} from the blackboard")
        if is_geo(text):
            if self.world is None:
                raise NoRoute("geographic points and no world to place them")
            return geo_to_enu(parse_geo(text), self.world.home)
        value = parse_value(text)
        if not (isinstance(value, tuple) and len(value) == 3 and all(isinstance(v, int | float) for v in value)):
            raise NoRoute(f"{node.type} {key}={text!r}")
        return (float(value[0]), float(value[1]), float(value[2]))

    def number(self, node: TreeNode, key: str, default: float) -> float:
        value = parse_value(node.ports[key]) if key in node.ports else default
        if not isinstance(value, int | float):
            raise NoRoute(f"{node.type} {key}={node.ports.get(key)!r}")
        return float(value)

    def fly(self, node: TreeNode, target: Vector, speed: float) -> None:
        start = self.position
        ceiling = self.config.ceiling
        if ceiling is not None and target[2] > ceiling + 1e-6:
            self.problem(node, f"({_fmt(target)}) is {target[2]:g} m above home, higher than the vehicle's ceiling "
                               f"of {ceiling:g} m (its profile, --vehicle)")
        self.check_leg(node, start, target)
        self.estimate.length += math.dist(start, target)
        self.spend(node, *self.model.fly(start, target, speed))
        self.position = target

    def check_leg(self, node: TreeNode, a: Vector, b: Vector) -> None:
        world = self.world
        if world is None:
            return
        fences = getattr(world, "fences", ())
        if fences:
            from aeroexec.drones.sim.geofence import breach

            steps = max(1, math.ceil(math.dist(a[:2], b[:2]) / FENCE_STEP))
            for i in range(1, steps):
                f = i / steps
                why = breach(fences, (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f))
                if why:
                    self.problem(node, f"the flight from ({_fmt(a)}) to ({_fmt(b)}) goes {why} on its way "
                                       f"(geofence)")
                    break
        if getattr(world, "obstacles", ()) and not world.segment_clear(a, b):
            self.problem(node, f"the straight flight from ({_fmt(a)}) to ({_fmt(b)}) crosses an obstacle: "
                               f"{node.type} flies around it, longer than estimated", severity="warning")

    # -- the tree ----------------------------------------------------------------------------------------------
    def run(self, node: TreeNode) -> None:
        kind = kind_of(node.type)
        if kind is not None:
            self.through(node, kind.route)
            return
        behavior = self.catalog.timed(node.type)
        if behavior is None:
            raise NoRoute(node.type)
        motion = _MOTIONS.get(behavior.motion)
        if motion is not None:
            motion(self, node)
        elif isinstance(behavior.duration, str):  # the argument that says how long
            if behavior.duration not in node.ports:
                raise NoRoute(f"{node.type} without {behavior.duration}")
            self.spend(node, self.number(node, behavior.duration, 0.0))
        elif behavior.duration is not None:
            self.spend(node, behavior.duration)
        else:
            raise NoRoute(node.type)

    def through(self, node: TreeNode, route: str) -> None:
        """A node of a kind: its ``route`` word says how the route goes through it."""
        if route == "series":
            for child in node.children:
                self.run(child)
        elif route == "repeat":
            cycles = self.number(node, "num_cycles", 1)
            if cycles == -1:  # a patrol forever: its route is one round, the time limit or the battery ends it
                self.estimate.forever = True
                cycles = 1
            elif cycles < 0:
                raise NoRoute(f"a {node.type} without end")
            for _ in range(int(min(cycles, 1000))):
                self.run(node.children[0])
        elif route == "parallel":
            flights = [c for c in node.children if not self.beside(c)]
            if len(flights) != 1:
                raise NoRoute(f"a {node.type} of several flights")
            self.run(flights[0])
        else:
            raise NoRoute(node.type)

    def beside(self, node: TreeNode) -> bool:
        behavior = self.catalog.timed(node.type)
        return behavior is not None and behavior.beside

    # -- the motions of the catalog's behaviors (``motion:``) -----------------------------------------------------
    def climb(self, node: TreeNode) -> None:
        altitude = self.number(node, "ALTITUDE", 2.0)
        self.flying = True
        self.spend(node, *self.model.take_off(altitude))
        self.estimate.length += altitude
        self.position = (self.position[0], self.position[1], self.position[2] + altitude)
        why = self.world.why_outside(self.position) if hasattr(self.world, "why_outside") else None
        if why:  # the points flown to are the specialist's to check; a take-off's height is this one's
            self.problem(node, f"{node.type} to {altitude:g} m climbs to ({_fmt(self.position)}), {why}")

    def fly_to(self, node: TreeNode) -> None:
        if "COORDINATES" in node.ports:
            target = self.point(node, "COORDINATES")
        else:
            delta = self.point(node, "RELATIVE_COORDINATES")
            target = tuple(p + d for p, d in zip(self.position, delta, strict=True))
        self.fly(node, target, self.number(node, "SPEED", self.config.cruise_speed))

    def follow_path(self, node: TreeNode) -> None:
        raise NoRoute(node.type)  # its points' form varies: not estimated

    def land(self, node: TreeNode) -> None:
        height = max(self.position[2], 0.0)
        self.spend(node, *self.model.land(height))
        self.estimate.length += height
        self.position = (self.position[0], self.position[1], 0.0)
        self.flying = False


_MOTIONS = {"climb": _Flight.climb, "fly_to": _Flight.fly_to, "descend": _Flight.land,
            "follow_path": _Flight.follow_path}


def _fmt(point: Vector) -> str:
    return ", ".join(f"{round(v, 1):g}" for v in point)


def _vehicle(config: Any) -> str:
    return f"its battery: {config.battery_hover_minutes:g} min of hover on a full charge"


def estimate_route(document: TreeDocument, world: Any = None, config: Any = None,
                   start: tuple[Vector, bool] | None = None, catalog: Any = None) -> RouteEstimate | None:
    """The route of ``document`` in ``world`` flown by the vehicle of ``config`` (default: the simulated
    multicopter's, its battery ``initial_battery_percent`` full), from ``start`` (where the drone is and whether it
    flies; default: home, on the ground), its behaviors' motions and durations ``catalog``'s (default: the aerial
    one); None when the tree is not a flight through known places."""
    from aeroexec.drones.sim import SimConfig
    from aeroexec.engine.catalog import default_catalog

    flight = _Flight(document, world, config or SimConfig(), start, catalog if catalog is not None else
                     default_catalog())
    try:
        flight.run(document.root)
    except (NoRoute, ValueError, KeyError, IndexError):
        return None
    if flight.flying:  # a mission that ends in the air: the flight's end lands the drone where it is
        flight.land(document.root)
    estimate = flight.estimate
    if flight.empty_at is not None:
        need = flight.estimate.failsafe - estimate.battery
        minutes = estimate.duration / 60.0
        used = flight.config.initial_battery_percent - estimate.battery
        flight.problem(flight.empty_at, f"the battery runs down to its {estimate.failsafe:g}% failsafe here: the "
                                        f"route ({estimate.length / 1000:.1f} km, {minutes:.0f} min) needs "
                                        f"{used + estimate.failsafe:.0f}% of a full battery, "
                                        f"{need:.0f}% more than the drone has ({_vehicle(flight.config)}); "
                                        f"a vehicle with more endurance: give its figures with --vehicle FILE")
    elif estimate.battery < RESERVE:
        flight.problem(document.root, f"the drone lands with {estimate.battery:.0f}% of its battery, below the "
                                      f"{RESERVE:g}% reserve pilots keep", severity="warning")
    return estimate


__all__ = ["RouteEstimate", "estimate_route"]
