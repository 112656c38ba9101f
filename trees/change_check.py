"""A change of a running tree checked like a new mission, before it takes effect: what is left to fly after the change
(the *remaining* mission), from where the drone is now.

- the new nodes, node by node, as verification checks a file's (Table 1: WRONG_FORMAT, WRONG_VALUE, the catalog's
  arguments and ranges, literal places against the world's bounds and obstacles, SubTree references);
- the flight order (WRONG_SEQUENCE) along every path of the remaining mission, from the phenomena's states now (the
  drone's beliefs: ``flight_state(self, hovering)``...), the behaviors running on taken as done;
- its route from the drone's position and battery now (the geofence and the battery left, ``trees.route``).

A problem counts against the change when the remaining mission without the change does not have it too: a change
that does not make a bad route worse (a shorter one, when the battery was already short) is taken. What a problem
says names the change's node where it is one (``change 3:1``), the mission's file and line otherwise.
"""

from __future__ import annotations

import dataclasses
import logging
from typing import Any

from aeroexec.beliefs import format_term
from aeroexec.drones.geodesy import enu_to_geodetic, geo_to_enu
from aeroexec.engine.catalog import BehaviorSpecialist
from aeroexec.engine.catalog.specialist import PhenomenonState
from aeroexec.engine.errors import WRONG_SEQUENCE, WRONG_VALUE, MissionProblem
from aeroexec.trees.model import PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.route import estimate_route
from aeroexec.trees.runtime.builder import model_of
from aeroexec.trees.runtime.changes import ChangePlan
from aeroexec.trees.runtime.nodes.controls import Sequence
from aeroexec.trees.runtime.nodes.decorators import Decorator, Repeat, SubTree
from aeroexec.trees.runtime.nodes.node_conditions import NodeConditions
from aeroexec.trees.runtime.nodes.parallels import Parallel, ParallelAll
from aeroexec.trees.runtime.ticking import RUNNING, SUCCESS
from aeroexec.trees.sequence_check import SequenceChecker
from aeroexec.trees.verify import TreeVerifier
from py_trees.behaviour import Behaviour

logger = logging.getLogger(__name__)
REMAINING = "remaining"  # the remaining mission's tree ID


class NoModel(Exception):
    """A running node that was not built from a model (a foreign leaf): the remaining mission is not known."""


# -- the remaining mission ------------------------------------------------------------------------------------
class Remaining:
    """What is left to run of a tree once ``plan`` is made, as a model: the running nodes from where they are (a
    sequence from its index, a Repeat's cycles left), what follows them whole. ``running`` holds the behavior leaves
    that go on running (copied), taken as done by the flight-order check."""

    def __init__(self, plan: ChangePlan | None) -> None:
        self.plan = plan
        self.running: list[TreeNode] = []
        self.active: set[int] = set()  # nodes a jump goes through: they go on from where it says
        if plan is not None:
            for node, _ in plan.cursors.values():
                self.active.add(id(node))
                parent = node.parent
                while parent is not None:
                    self.active.add(id(parent))
                    parent = parent.parent

    def tree(self, root: Behaviour) -> TreeNode | None:
        return self.of(root)

    def goes_on(self, node: Behaviour) -> bool:
        halted = self.plan is not None and any(node is h for h in self.plan.halted)
        return (node.status is RUNNING and not halted) or id(node) in self.active

    def children(self, node: Behaviour) -> list[Any]:
        return self.plan.children(node) if self.plan is not None else list(node.children)

    def index(self, node: Behaviour) -> int:
        if self.plan is not None:
            index = self.plan.index(node)
            return 0 if index is None else index
        return node.index if node.status is RUNNING else 0

    def of(self, node: Any) -> TreeNode | None:
        if isinstance(node, TreeNode):
            return node
        model = model_of(node)
        if model is None:
            raise NoModel(node.name)
        if not self.goes_on(node):
            return model
        if isinstance(node, NodeConditions):  # started: its pre-conditions are behind it
            inner = self.of_inner(node.decorated, model)
            return None if inner is None else dataclasses.replace(
                inner, ports={k: v for k, v in inner.ports.items() if k not in PRECONDITIONS})
        return self.of_inner(node, model)

    def of_inner(self, node: Behaviour, model: TreeNode) -> TreeNode | None:
        if isinstance(node, Sequence):
            children = self.children(node)
            index = self.index(node)
            parts = [self.of(children[index])] if index < len(children) else []
            parts += [self.whole(c) for c in children[index + 1:]]
            kept = [p for p in parts if p is not None]
            return dataclasses.replace(model, children=kept) if kept else None
        if isinstance(node, SubTree):
            return self.of(node.children[0])
        if isinstance(node, Repeat):
            rest = self.of(node.decorated)
            if node.counted is not SUCCESS:  # RetryUntilSuccessful: what runs now, then (taken) success
                return rest
            try:
                cycles = int(node.cycles_port.get())
            except Exception:  # read from a blackboard that cannot say: all of it again
                return model
            more = cycles - node.count - 1 if cycles >= 0 else -1
            parts = [rest] if rest is not None else []
            if more != 0:
                parts.append(dataclasses.replace(model, ports={**model.ports, node.port: str(more)},
                                                 children=[self.whole(node.decorated)]))
            return TreeNode("Sequence", model.name, {}, parts, model.file, model.line) if parts else None
        if isinstance(node, Decorator):
            child = self.of(node.decorated)
            return None if child is None else dataclasses.replace(model, children=[child])
        if isinstance(node, Parallel | ParallelAll):
            done = getattr(node, "completed", set())
            children = [self.of(c) for i, c in enumerate(self.children(node)) if i not in done]
            kept = [c for c in children if c is not None]
            return dataclasses.replace(model, children=kept) if kept else None
        if not node.children:
            copy = dataclasses.replace(model)
            self.running.append(copy)
            return copy
        children = [self.of(c) if self.goes_on(c) else self.whole(c) for c in self.children(node)]
        return dataclasses.replace(model, children=[c for c in children if c is not None])

    @staticmethod
    def whole(node: Any) -> TreeNode | None:
        return node if isinstance(node, TreeNode) else model_of(node)


# -- where the drone is --------------------------------------------------------------------------------------
def current_states(engine: Any) -> dict[str, PhenomenonState | None]:
    """Each phenomenon's state as the drone believes it now (``flight_state(self, S)``, ``light(self, S)``), with
    the last behavior that brought it there; None where the beliefs do not say."""
    catalog = engine.catalog
    states: dict[str, PhenomenonState | None] = {}
    achieved = None
    for name, phenomenon in catalog.phenomena.items():
        value = None
        for predicate in (f"{name}_state", name):
            try:
                answers = engine.memory.query_all(f"{predicate}(self, ?S)")
            except Exception:  # a predicate this robot does not have
                continue
            found = [format_term(a.get("?S", a.get("S"))).strip("'\"") for a in answers]
            value = next((v for v in found if v in phenomenon.states), None)
            if value is not None:
                break
        if value is None:
            states[name] = None
            continue
        if achieved is None:
            achieved = engine.log.events("GOAL_ACHIEVED")
        movers = {b for t in catalog.transitions if t.phenomenon == name for b in t.behaviors}
        since = next((e.behavior for e in reversed(achieved) if e.behavior in movers), None)
        states[name] = PhenomenonState(value, since)
    return states


class _FromNow(BehaviorSpecialist):
    """A specialist whose missions start from the states of now, not from the catalog's initial ones."""

    def __init__(self, catalog: Any, world: Any, now: dict[str, PhenomenonState | None]) -> None:
        super().__init__(catalog, world)
        self.now = now

    def initial_states(self, overrides: Any = None) -> dict[str, Any]:  # type: ignore[override]
        return dict(self.now) if overrides is None else super().initial_states(overrides)


class _RemainingOrder(SequenceChecker):
    """The flight order of the remaining mission; the behaviors running on are taken as done, silently."""

    def __init__(self, document: TreeDocument, specialist: BehaviorSpecialist, report: Any,
                 running: list[TreeNode]) -> None:
        super().__init__(document, specialist, report)
        self.running = {id(node) for node in running}

    def behavior(self, node: TreeNode, behavior: str, state: Any) -> Any:
        if id(node) in self.running:
            return self.quietly(lambda: super(_RemainingOrder, self).behavior(node, behavior, state))
        return super().behavior(node, behavior, state)


def drone_start(engine: Any, world: Any) -> tuple[tuple[float, float, float], bool]:
    """Where the drone is now in ``world``'s frame (its home may differ from the drone's), and whether it flies."""
    from aeroexec.drones import LandedState

    telemetry = engine.drone.telemetry()
    position = tuple(float(v) for v in telemetry.position)
    home, world_home = getattr(telemetry, "home", None), getattr(world, "home", None)
    if home is not None and world_home is not None and tuple(home) != tuple(world_home):
        position = geo_to_enu(enu_to_geodetic(position, home), world_home)
    flying = telemetry.landed_state not in (LandedState.ON_GROUND, LandedState.UNKNOWN)
    return position, flying  # type: ignore[return-value]


# -- the check -----------------------------------------------------------------------------------------------
def check_change(mission: Any, plan: ChangePlan, world: Any = None, config: Any = None) -> list[MissionProblem]:
    """The errors ``plan`` brings to the running ``mission`` (empty: the change may be made)."""
    engine = mission.engine
    catalog = engine.catalog
    problems = _node_problems(mission.document, catalog, world, plan.new)
    try:
        before, after = Remaining(None), Remaining(plan)
        old, new = before.tree(mission.root), after.tree(mission.root)
    except NoModel as missing:
        logger.info("the remaining mission is not known (%s is no model's node): its order and route are not "
                    "checked", missing)
        return problems
    states = current_states(engine)
    problems += _new_only(_order(mission.document, old, before.running, catalog, world, states),
                          _order(mission.document, new, after.running, catalog, world, states))
    if world is not None:
        problems += _route_problems(mission.document, old, new, world, config, engine)
    return problems


def check_new_mission(document: TreeDocument, engine: Any, world: Any = None, config: Any = None
                      ) -> list[MissionProblem]:
    """A mission loaded into the running flight, from where the drone is now: its flight order from the phenomena's
    states now and its route from the drone's position and battery (the rest of its check is the file's own)."""
    states = current_states(engine)
    problems = _order(document, document.root, [], engine.catalog, world, states)
    if world is not None:
        problems += _route(document, document.root, world, config, engine)[0]
    return problems


def _node_problems(document: TreeDocument, catalog: Any, world: Any, nodes: list[TreeNode]) -> list[MissionProblem]:
    if not nodes:
        return []
    verifier = TreeVerifier(document, catalog, world=world)
    for node in nodes:
        for inner in node.walk():
            verifier.check_node(inner)
    return [p for p in verifier.problems if p.severity == "error"]


def _document(document: TreeDocument, root: TreeNode | None) -> TreeDocument:
    trees = {**document.trees, REMAINING: root if root is not None else TreeNode("AlwaysSuccess", REMAINING)}
    return TreeDocument(trees, REMAINING, document.file, document.lines)


def _order(document: TreeDocument, root: TreeNode | None, running: list[TreeNode], catalog: Any, world: Any,
           states: dict[str, PhenomenonState | None]) -> list[MissionProblem]:
    found: list[MissionProblem] = []

    def report(node: TreeNode, message: str, kind: str) -> None:
        found.append(MissionProblem("error", message, node.file or document.file, node.line, kind))

    if root is not None:
        _RemainingOrder(_document(document, root), _FromNow(catalog, world, states), report, running).check()
    return [p for p in found if p.kind == WRONG_SEQUENCE]


def _route(document: TreeDocument, root: TreeNode | None, world: Any, config: Any, engine: Any
           ) -> tuple[list[MissionProblem], Any]:
    from aeroexec.drones.sim import SimConfig

    if root is None:
        return [], None
    vehicle = config if config is not None else getattr(engine.drone, "config", None)
    if not isinstance(vehicle, SimConfig):
        vehicle = SimConfig()
    battery = float(engine.drone.telemetry().battery_percent)
    vehicle = dataclasses.replace(vehicle, initial_battery_percent=battery)
    estimate = estimate_route(_document(document, root), world, vehicle, drone_start(engine, world), engine.catalog)
    if estimate is None:
        return [], None
    return [p for p in estimate.problems if p.severity == "error"], estimate


def _route_problems(document: TreeDocument, old: TreeNode | None, new: TreeNode | None, world: Any, config: Any,
                    engine: Any) -> list[MissionProblem]:
    before, old_estimate = _route(document, old, world, config, engine)
    after, new_estimate = _route(document, new, world, config, engine)
    if new_estimate is None:
        return []
    empty = new_estimate.battery < new_estimate.failsafe
    worse = old_estimate is None or new_estimate.battery < old_estimate.battery - 0.5
    battery = [p for p in after if "battery runs down" in p.message]
    others = _new_only([p for p in before if p not in battery], [p for p in after if p not in battery])
    if empty and worse:
        others += battery or [MissionProblem("error", "the battery left does not last the changed route",
                                             document.file, 0, WRONG_VALUE)]
    return others


def _new_only(before: list[MissionProblem], after: list[MissionProblem]) -> list[MissionProblem]:
    """The problems of ``after`` that ``before`` does not have (by message)."""
    known = {p.message for p in before}
    return [p for p in after if p.message not in known]


__all__ = ["Remaining", "check_change", "check_new_mission", "current_states"]
