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

TYPE_CHECKING = False
if TYPE_CHECKING:  # the planners are imported when a route or a point to explore is first asked for (a run whose
    # behaviors plan nothing never imports them: the grid, the search and the coverage, ~4 ms of a start)
    from aeroexec.engine.planning.exploration import ExplorationSettings, ExplorationStore
    from aeroexec.engine.planning.path_planner import PlannerSettings, Point

logger = logging.getLogger(__name__)

MARK_PERIOD = 0.2  # s between two coverage updates of the exploration planner process
_STORE_ATTRIBUTE = "exploration_store"
EXPLORATION_MARGIN = 3.0  # m from obstacles, as the aerial catalog's GO_TO_POINT precondition asks


def planner_settings(settings: EngineSettings) -> PlannerSettings:
    """The path planner's settings from the engine's (``planning_resolution``, ``planning_margin``)."""
    from aeroexec.engine.planning.path_planner import PlannerSettings

    extra, default = settings.extra, PlannerSettings()
    return PlannerSettings(resolution=float(extra.get("planning_resolution", default.resolution)),
                           margin=float(extra.get("planning_margin", default.margin)))


def exploration_settings(settings: EngineSettings) -> ExplorationSettings:
    """The exploration planner's settings from the engine's (``exploration_*`` keys of ``extra``)."""
    from aeroexec.engine.planning.exploration import ExplorationSettings

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
        from aeroexec.engine.planning.exploration import ExplorationStore

        store = ExplorationStore(exploration_settings(context.settings), getattr(context, "obstacles", None))
        setattr(context, _STORE_ATTRIBUTE, store)
    return store


def _point(value: Any) -> Point:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


class RouteRequest:
    """A route asked of the path planner. What a few distance queries decide is answered at once (no map, a clear
    straight line, a destination out of bounds or too near an obstacle); a grid search goes to the engine's planning
    worker after :meth:`submit`, and :meth:`answer` is ``(waypoints, detail)`` once it is back, None before."""

    def __init__(self, context: BehaviorContext, destination: Any, start: Any = None) -> None:
        self.context = context
        self.destination = _point(destination)
        self.start = _point(context.drone.telemetry().position if start is None else start)
        self.error = ""  # the planner gave no answer (it failed or took too long), rather than finding no path
        self._answer: tuple[list[Point], str] | None = None
        self._job: Any = None
        self.planner: Any = None
        if context.obstacles is None:
            self._answer = [self.destination], f"no obstacle map: the straight line to {list(self.destination)}"
            return
        from aeroexec.engine.planning.path_planner import PathPlanner

        self.planner = PathPlanner(context.obstacles, planner_settings(context.settings))
        quick = self.planner.quick(self.start, self.destination)
        if quick is not None:
            self._answer = self._described(quick, self.planner.reason)

    def _described(self, points: list[Point], reason: str) -> tuple[list[Point], str]:
        if not points:
            return [], f"no path to {list(self.destination)}: {reason}"
        return points, f"{len(points)} waypoints to {list(self.destination)}"

    @property
    def searching(self) -> bool:
        """A grid search is needed (or under way)."""
        return self._answer is None

    def submit(self) -> None:
        """Start the search on the planning worker (on this thread when the context has none)."""
        if self._answer is not None or self._job is not None:
            return
        worker = getattr(self.context, "planning", None)
        planner, start, destination = self.planner, self.start, self.destination
        if worker is None:
            self._answer = self._described(planner.plan(start, destination), planner.reason)
            return
        self._job = worker.submit(f"path to {list(destination)}",
                                  lambda: (planner.plan(start, destination), planner.reason))

    def answer(self, now: float) -> tuple[list[Point], str] | None:
        """``(waypoints, detail)`` once known at engine time ``now``; ``([], detail)`` when there is no path."""
        job = self._job
        if self._answer is None and job is not None and job.ready(now):
            if job.error:
                self.error = job.error
                self._answer = [], f"no path to {list(self.destination)}: {job.error}"
            else:
                self._answer = self._described(*job.result)
        return self._answer

    @property
    def cancelled(self) -> bool:
        """The search was handed to the worker and its answer is no longer wanted."""
        return self._job is not None and self._job.cancelled

    def cancel(self) -> None:
        """Nobody waits for the answer any more."""
        if self._job is not None:
            self._job.cancel()


class GeneratePathFreeOfObstacles(BehaviorProcess):
    """GENERATE_PATH_FREE_OF_OBSTACLES: a path from where the drone is to DESTINATION keeping the safety margin.

    Result: the waypoints after the current position, ``[[x, y, z], ...]`` ending at DESTINATION, or ``[]``
    when no path exists; also believed as ``path(DESTINATION, Points)``. A grid search runs on the planning
    worker: the behavior is RUNNING until its answer is back (its timeout counts, and it can be stopped).
    """

    behavior = "GENERATE_PATH_FREE_OF_OBSTACLES"

    def on_start(self) -> None:
        self.request = RouteRequest(self.context, self.arguments["DESTINATION"])
        self.request.submit()

    def on_run(self) -> Outcome | None:
        answer = self.request.answer(self.now())
        if answer is None:
            return None
        if self.request.error:
            return self.fail(self.request.error)
        points, detail = answer
        self.result = [[round(v, 3) for v in p] for p in points]
        self.context.log.record("path_planned", self.name, detail, waypoints=len(points))
        self.memory.add(Struct("path", (self.request.destination, ListTerm(tuple(p) for p in self.result))))
        return Outcome.GOAL_ACHIEVED

    def on_stop(self, outcome: Outcome) -> None:
        self.request.cancel()


class GenerateNextPointToExplore(BehaviorProcess):
    """GENERATE_NEXT_POINT_TO_EXPLORE: the next point of REGION's coverage not yet visited.

    Result: ``[x, y, z]``, or ``[]`` once the region is covered; also believed as
    ``next_point_to_explore(REGION, Point)``. Consecutive requests for the same REGION continue its coverage;
    the first plans the region's coverage on the planning worker (RUNNING until it is back).
    """

    behavior = "GENERATE_NEXT_POINT_TO_EXPLORE"

    def on_start(self) -> None:
        self.region = [_point(p) for p in self.arguments["REGION"]]
        self._error = ""
        self._job = None
        store = exploration_store(self.context)
        worker = getattr(self.context, "planning", None)
        if worker is not None and not store.has(self.region):
            region = self.region

            def cover() -> Any:
                try:
                    return store.new_planner(region)
                except ValueError as error:  # a region that cannot be covered: the request's failure
                    return error

            self._job = worker.submit(f"exploration of {region}", cover)

    def on_run(self) -> Outcome | None:
        store = exploration_store(self.context)
        if self._job is not None:
            if not self._job.ready(self.now()):
                return None
            if self._job.error:
                return self.fail(self._job.error)
            if isinstance(self._job.result, ValueError):
                return self.fail(str(self._job.result))
            store.adopt(self._job.result)
            self._job = None
        try:
            planner = store.planner(self.region)
        except ValueError as error:
            return self.fail(str(error))
        point = planner.next_point(self.telemetry().position)
        self.result = [round(v, 3) for v in point] if point is not None else []
        detail = (f"next point {self.result}, {planner.remaining} left" if point is not None
                  else f"the region is covered ({len(planner.skipped)} points given up)")
        self.context.log.record("exploration_planned", self.name, detail, remaining=planner.remaining)
        self.memory.add(Struct("next_point_to_explore", (ListTerm(self.region), tuple(self.result) if self.result
                                                         else ListTerm())))
        return Outcome.GOAL_ACHIEVED

    def on_stop(self, outcome: Outcome) -> None:
        if self._job is not None:
            self._job.cancel()


class PathPlannerProcess(Process):
    """path_planner: the capability's process. Occupancy grids are built lazily, by the planning worker, for the
    first search that needs one (a clear straight line needs none), and cached per map."""


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
