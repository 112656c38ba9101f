"""The behavior process (paper section 4.1, Algorithms 1-3): the base class every behavior implementation extends.

A subclass says how to check the situation, start, monitor each tick and stop;
the coordinator runs the generic part of the algorithms (resources, timer,
timeout, events). Subclasses register by behavior name in a :class:`BehaviorLibrary`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.beliefs import BeliefMemory
from aeroexec.drones import Drone, Telemetry
from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.catalog.descriptors import BehaviorDescriptor
from aeroexec.engine.catalog.engine_behaviors import KEEP_HOVERING
from aeroexec.engine.events import EventLog, Outcome

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, ClassVar

logger = logging.getLogger(__name__)


@dataclass
class EngineSettings:
    """Tolerances and defaults the behaviors share; an embedding engine may change them."""

    position_tolerance: float = 0.3  # m: a point is reached within this distance
    yaw_tolerance: float = 5.0  # degrees
    default_altitude: float = 2.0  # m: TAKE_OFF without ALTITUDE
    hover_altitude_tolerance: float = 0.25  # m
    stall_time: float = 8.0  # s without progress toward a goal -> WRONG_PROGRESS
    command_timeout: float = 10.0  # s for a drone command to be accepted
    cruise_speed: float = 5.0  # m/s the travel-time estimate assumes
    climb_rate: float = 1.5  # m/s a take-off climbs at (PX4's MPC_TKO_SPEED): its timeout grows with the altitude
    descent_rate: float = 0.7  # m/s the slowest landing descends at (MPC_LAND_SPEED): LAND's timeout grows with it
    hold_behavior: str = KEEP_HOVERING  # what holds the robot where it is while the operator pauses
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass
class BehaviorContext:
    """What a behavior may use: the drone, the belief memory, the clock, the catalog, the event log."""

    drone: Drone
    memory: BeliefMemory
    clock: Callable[[], float]
    catalog: BehaviorCatalog
    log: EventLog
    settings: EngineSettings = field(default_factory=EngineSettings)
    obstacles: Any = None  # an ObstacleMap (distance_to_obstacle, maybe bounds) or None when nothing is known
    refresh: Callable[[], None] = lambda: None  # bring the drone's own beliefs up to date now
    operator: Any = None  # the operator channel (notify, ask) of this run; None: messages are only logged
    bus: Any = None  # the message bus shared with the other drones of the run; None: flying alone
    output_dir: Path | None = None  # where photos, videos and maps of this run are written
    position_source: Any = None  # a PositionSource: whether the telemetry or an estimator writes position(self)
    planning: Any = None  # the PlanningWorker searches run on (engine/planning/worker.py); None: on the caller

    def now(self) -> float:
        return self.clock()

    @property
    def robot(self) -> Any:
        """The robot the engine drives (``drone`` is the same object, named for the aerial behaviors)."""
        return self.drone


@dataclass(frozen=True, slots=True)
class Situation:
    """Why a behavior should not start: its preconditions fail, or its goal is already achieved."""

    outcome: Outcome
    reason: str


class BehaviorProcess:
    """One execution of a behavior. Override :meth:`on_start`, :meth:`on_run` and, when needed, the others.

    ``on_run`` is called every tick while the behavior runs and returns
    ``Outcome.GOAL_ACHIEVED`` or ``Outcome.WRONG_PROGRESS`` (with :meth:`fail`)
    to finish, or ``None`` to continue. Timeouts are the coordinator's job.
    """

    behavior: ClassVar[str] = ""  # the catalog name this class implements

    def __init__(self, descriptor: BehaviorDescriptor, arguments: dict[str, Any], context: BehaviorContext) -> None:
        self.descriptor = descriptor
        self.arguments = arguments
        self.context = context
        self.started_at = context.now()
        self.reason = ""  # why it failed, for the operator
        self.result: Any = None  # what a deliberative behavior found
        self.bindings: dict[str, Any] = {}  # extra variables for the catalog preconditions (e.g. ?DESTINATION)

    # -- conveniences -------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.descriptor.name

    @property
    def drone(self) -> Drone:
        return self.context.drone

    @property
    def robot(self) -> Any:
        """The robot the engine drives, whatever its kind (a rover's behaviors use its own commands)."""
        return self.context.drone

    @property
    def memory(self) -> BeliefMemory:
        return self.context.memory

    @property
    def settings(self) -> EngineSettings:
        return self.context.settings

    def now(self) -> float:
        return self.context.clock()  # the context's now(), one call fewer (a motion behavior asks it every period)

    @property
    def elapsed(self) -> float:
        return self.context.clock() - self.started_at

    def telemetry(self) -> Telemetry:
        return self.context.drone.telemetry()

    def expected_duration(self) -> float | None:
        """Seconds the work asked should take (a flight's distance at its speed), asked once its situation was
        checked (after :meth:`prepare`): the catalog's timeout grows by 1.5 times it. None: the catalog's timeout
        as it is (a request's own timeout is never changed)."""
        return None

    def fail(self, reason: str) -> Outcome:
        """Finish with WRONG_PROGRESS, saying why."""
        self.reason = reason
        return Outcome.WRONG_PROGRESS

    # -- the algorithms' specific steps ---------------------------------------------
    def prepare(self) -> None:
        """Compute what the preconditions need (e.g. bind ``?DESTINATION``) before they are checked."""

    def check_situation(self) -> Situation | None:
        """Behavior-specific checks after the catalog's preconditions; None when the behavior can start."""
        return None

    def resume_from(self, paused: BehaviorProcess) -> None:
        """Take over what ``paused`` (this request's process, stopped by the operator's pause) had done, so the
        resumed behavior continues rather than starts again (TAKE_OFF keeps its target altitude)."""

    def on_start(self) -> None:
        """Extract arguments, connect and initiate (Algorithm 1, steps 3-5)."""

    def on_run(self) -> Outcome | None:
        """Monitor one tick (Algorithm 2): GOAL_ACHIEVED, WRONG_PROGRESS, or None to go on (FAILED_PRECONDITIONS,
        with :attr:`reason`, when the behavior finds out only while running that it cannot be executed)."""
        return None

    def on_stop(self, outcome: Outcome) -> None:
        """Write end values (Algorithm 3, step 1); ``outcome`` says why the behavior ends."""


class BehaviorLibrary:
    """Behavior implementations by catalog name. A library may also know behaviors by the module that implements
    them (:meth:`served_by_module`): the module is imported when one of its behaviors is first asked for, so a run
    imports the modules of the behaviors it uses."""

    def __init__(self, classes: Iterable[type[BehaviorProcess]] = ()) -> None:
        self._classes: dict[str, type[BehaviorProcess]] = {}
        self._modules: dict[str, str] = {}  # name -> the module implementing it, not imported yet
        for cls in classes:
            self.register(cls)

    def register(self, cls: type[BehaviorProcess], name: str | None = None) -> None:
        name = name or cls.behavior
        if not name:
            raise ValueError(f"{cls.__name__} does not say which behavior it implements (set behavior = 'NAME')")
        self._classes[name] = cls
        self._modules.pop(name, None)

    def served_by_module(self, name: str, module: str) -> None:
        """``name`` is implemented by a :class:`BehaviorProcess` subclass of ``module`` whose ``behavior`` is
        ``name``, registered when first asked for (a later :meth:`register` of the name wins)."""
        self._classes.pop(name, None)
        self._modules[name] = module

    def get(self, name: str) -> type[BehaviorProcess] | None:
        cls = self._classes.get(name)
        if cls is None and name in self._modules:
            cls = self._load(name)
        return cls

    def _load(self, name: str) -> type[BehaviorProcess] | None:
        import importlib

        module = importlib.import_module(self._modules[name])
        for value in vars(module).values():
            if isinstance(value, type) and issubclass(value, BehaviorProcess) and \
                    value.__module__ == module.__name__ and value.behavior in self._modules and \
                    self._modules[value.behavior] == module.__name__:
                self.register(value)
        return self._classes.get(name)

    def __contains__(self, name: object) -> bool:
        return name in self._classes or name in self._modules

    def names(self) -> set[str]:
        return set(self._classes) | set(self._modules)


def distance(a: Iterable[float], b: Iterable[float]) -> float:
    return math.dist(tuple(a), tuple(b))
