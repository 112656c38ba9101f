"""Deliberative planning behaviors (paper Table A.3): GENERATE_PATH_FREE_OF_OBSTACLES and
GENERATE_NEXT_POINT_TO_EXPLORE, and the capability processes ``path_planner`` and ``exploration_planner``.

The path comes from :mod:`aeroexec.engine.planning.path_planner` over the engine's obstacle map (``context.obstacles``);
without a map the path is the straight line to the destination, and the event log says so. Exploration
progress lives in an :class:`~aeroexec.engine.planning.exploration.ExplorationStore` kept on the behavior context, so it
survives the planner process being stopped between two requests; while ``exploration_planner`` runs, it covers
the points the drone flies over.

Settings read from ``EngineSettings.extra``: ``planning_resolution`` (m, 0.5), ``planning_margin`` (m, 1.0),
``exploration_footprint`` (m, 6.0), ``exploration_overlap`` (0.2), ``exploration_reach`` (m, 1.0),
``exploration_margin`` (m, 3.0).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from aeroexec.beliefs import ListTerm, Struct
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorContext, BehaviorProcess, EngineSettings
from aeroexec.engine.execution.resources import Process
from aeroexec.engine.planning.exploration import ExplorationSettings, ExplorationStore
from aeroexec.engine.planning.path_planner import PathPlanner, PlannerSettings, Point, map_bounds

logger = logging.getLogger(__name__)

MARK_PERIOD = 0.2  # s between two coverage updates of the exploration planner process
_STORE_ATTRIBUTE = "exploration_store"
EXPLORATION_MARGIN = 3.0  # m from obstacles, as the aerial catalog's GO_TO_POINT precondition asks


def planner_settings(settings: EngineSettings) -> PlannerSettings:
    """The path planner's settings from the engine's (``planning_resolution``, ``planning_margin``)."""
    extra, default = settings.extra, PlannerSettings()
    return PlannerSettings(resolution=float(extra.get("planning_resolution", default.resolution)),
                           margin=float(extra.get("planning_margin", default.margin)))


def exploration_settings(settings: EngineSettings) -> ExplorationSettings:
    """The exploration planner's settings from the engine's (``exploration_*`` keys of ``extra``)."""
    extra, default = settings.extra, ExplorationSettings()
    return ExplorationSettings(footprint=float(extra.get("exploration_footprint", default.footprint)),
                               overlap=float(extra.get("exploration_overlap", default.overlap)),
                               reach=float(extra.get("exploration_reach", default.reach)),
                               # a point to explore must be a valid GO_TO_POINT destination (its precondition
                               # asks 3 m from obstacles)
                               margin=float(extra.get("exploration_margin", EXPLORATION_MARGIN)))


def exploration_store(context: BehaviorContext) -> ExplorationStore:
    """The run's exploration memory, created on first use and kept on the behavior context."""
    store = getattr(context, _STORE_ATTRIBUTE, None)
    if store is None:
        store = ExplorationStore(exploration_settings(context.settings), getattr(context, "obstacles", None))
        setattr(context, _STORE_ATTRIBUTE, store)
    return store


def _point(value: Any) -> Point:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


def plan_route(context: BehaviorContext, destination: Any, start: Any = None) -> tuple[list[Point], str]:
    """Waypoints from ``start`` (the drone's position by default; excluded) to ``destination`` avoiding the
    context's obstacles with the planning margin, and a sentence saying what was found; ``[]`` when no path exists.

    Without an obstacle map the route is the straight line ``[destination]``. Motion behaviors call this too.
    """
    destination = _point(destination)
    start = _point(context.drone.telemetry().position if start is None else start)
    if context.obstacles is None:
        return [destination], f"no obstacle map: the straight line to {list(destination)}"
    planner = PathPlanner(context.obstacles, planner_settings(context.settings))
    points = planner.plan(start, destination)
    if not points:
        return [], f"no path to {list(destination)}: {planner.reason}"
    return points, f"{len(points)} waypoints to {list(destination)}"


class GeneratePathFreeOfObstacles(BehaviorProcess):
    """GENERATE_PATH_FREE_OF_OBSTACLES: a path from where the drone is to DESTINATION keeping the safety margin.

    Result: the waypoints after the current position, ``[[x, y, z], ...]`` ending at DESTINATION, or ``[]``
    when no path exists; also believed as ``path(DESTINATION, Points)``.
    """

    behavior = "GENERATE_PATH_FREE_OF_OBSTACLES"

    def on_start(self) -> None:
        destination = _point(self.arguments["DESTINATION"])
        points, detail = plan_route(self.context, destination)
        self.result = [[round(v, 3) for v in p] for p in points]
        self.context.log.record("path_planned", self.name, detail, waypoints=len(points))
        self.memory.add(Struct("path", (destination, ListTerm(tuple(p) for p in self.result))))

    def on_run(self) -> Outcome | None:
        return Outcome.GOAL_ACHIEVED


class GenerateNextPointToExplore(BehaviorProcess):
    """GENERATE_NEXT_POINT_TO_EXPLORE: the next point of REGION's coverage not yet visited.

    Result: ``[x, y, z]``, or ``[]`` once the region is covered; also believed as
    ``next_point_to_explore(REGION, Point)``. Consecutive requests for the same REGION continue its coverage.
    """

    behavior = "GENERATE_NEXT_POINT_TO_EXPLORE"

    def on_start(self) -> None:
        region = [_point(p) for p in self.arguments["REGION"]]
        self._error = ""
        try:
            planner = exploration_store(self.context).planner(region)
        except ValueError as error:
            self._error = str(error)
            return
        point = planner.next_point(self.telemetry().position)
        self.result = [round(v, 3) for v in point] if point is not None else []
        detail = (f"next point {self.result}, {planner.remaining} left" if point is not None
                  else f"the region is covered ({len(planner.skipped)} points given up)")
        self.context.log.record("exploration_planned", self.name, detail, remaining=planner.remaining)
        self.memory.add(Struct("next_point_to_explore", (ListTerm(region), tuple(self.result) if self.result
                                                         else ListTerm())))

    def on_run(self) -> Outcome | None:
        if self._error:
            return self.fail(self._error)
        return Outcome.GOAL_ACHIEVED


class PathPlannerProcess(Process):
    """path_planner: builds the occupancy grid of the obstacle map when it starts, so plans come at once."""

    def on_start(self) -> None:
        obstacles = getattr(self.context, "obstacles", None)
        if obstacles is not None and map_bounds(obstacles) is not None:
            PathPlanner(obstacles, planner_settings(self.context.settings)).grid()


class ExplorationPlannerProcess(Process):
    """exploration_planner: while it runs, the points the drone passes near count as explored."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self._last: float | None = None

    def step(self, now: float) -> None:
        if self._last is not None and now - self._last < MARK_PERIOD - 1e-9:
            return
        self._last = now
        exploration_store(self.context).mark(self.context.drone.telemetry().position)


PLANNING_BEHAVIORS: list[type[BehaviorProcess]] = [GeneratePathFreeOfObstacles, GenerateNextPointToExplore]
PLANNING_PROCESSES: dict[str, Callable[[str], Process]] = {"path_planner": PathPlannerProcess,
                                                           "exploration_planner": ExplorationPlannerProcess}
