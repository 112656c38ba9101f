"""The execution engine: one loop at a fixed rate that drives the drone, the beliefs, the behaviors and the mission.

Each tick: read the clock, let the drone integrate or refresh, record its
events, run the belief updaters, step the capability processes, monitor the
active behaviors and run the reactive rules, then serve the mission. Build one
with :class:`Engine` and either ``run()`` it in this thread or ``start()`` it in
its own.
"""

from __future__ import annotations

import contextlib
import heapq
import logging
import threading
import time
from collections.abc import Callable, Iterable
from pathlib import Path

from aeroexec.beliefs import BeliefMemory, BeliefUpdater, Rule
from aeroexec.drones import Robot
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.catalog import BehaviorCatalog, BehaviorSpecialist, default_catalog
from aeroexec.engine.clock import Clock, SimulatedClock
from aeroexec.engine.events import EventLog
from aeroexec.engine.execution.coordinator import BehaviorCoordinator
from aeroexec.engine.execution.process import BehaviorContext, BehaviorLibrary, EngineSettings
from aeroexec.engine.execution.resources import ProcessRegistry, ResourceManager
from aeroexec.engine.execution.updaters import TELEMETRY_PREDICATES, ObstacleMap, TelemetryUpdater, register_computed
from aeroexec.engine.library import default_library, default_processes
from aeroexec.engine.missions.bridge import DONE, MissionBridge, MissionPreempted
from aeroexec.engine.planning.worker import PLAN_TIME, WAIT_LIMIT, PlanningWorker
from aeroexec.engine.safety import SafetyPredicates
from aeroexec.engine.supervision.supervisor import Supervisor

from aeroexec.limits import RULES_WORK_PER_STEP, RULES_WORK_WHY

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.engine.safety import SafetyMonitor

logger = logging.getLogger(__name__)


class Timers:
    """Callbacks due at a time of the engine's clock, run by the loop (e.g. a mission's ``wait``)."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        #: the callbacks to run, a heap by their time (empty: :meth:`run_due` has nothing to do)
        self.scheduled: list[tuple[float, int, Callable[[], None]]] = []
        self._count = 0

    def after(self, seconds: float, callback: Callable[[], None]) -> None:
        self._count += 1
        heapq.heappush(self.scheduled, (self._clock() + seconds, self._count, callback))

    def run_due(self) -> None:
        due = self.scheduled
        if not due:
            return
        now = self._clock()
        while due and due[0][0] <= now + 1e-9:
            _, _, callback = heapq.heappop(due)
            try:
                callback()
            except Exception:
                logger.exception("a timer callback failed")


class Engine:
    """Everything of the paper's execution engine wired together around one robot (a drone by default).

    ``telemetry`` is the updater of the robot's beliefs about itself; without it, a drone's telemetry beliefs
    (``position``, ``flight_state``, ``charge``...) are written. A robot of another kind passes its own, and
    ``described_in``: the catalog its behaviors' implementations are described in (a thin catalog takes their
    arguments from it; default: the aerial catalog). ``rules`` derive beliefs besides the catalog's own
    ``rules:`` (``aeroexec.beliefs.read_rules(path)`` reads a rules file; ``catalog.with_rules(rules)`` is the same):
    checked against the catalog, they raise :class:`~aeroexec.beliefs.RuleError` with each problem's file and line.
    ``vehicle``: the vehicle model the safety rules estimate with (default: the simulator's figures when the robot
    is one, else the defaults; ``aeroexec run --vehicle FILE`` gives a profile's).
    """

    def __init__(self, drone: Robot, *, catalog: BehaviorCatalog | None = None,
                 library: BehaviorLibrary | None = None, processes: ProcessRegistry | None = None,
                 clock: Clock | None = None, rate: float = 20.0, settings: EngineSettings | None = None,
                 updaters: Iterable[BeliefUpdater] = (), obstacles: ObstacleMap | None = None,
                 capability_grace: float = 2.0, belief_period: float = 0.1, operator: Any = None,
                 bus: Any = None, output_dir: str | Path | None = None,
                 telemetry: BeliefUpdater | None = None, described_in: BehaviorCatalog | None = None,
                 rules: Iterable[Rule] = (), vehicle: VehicleModel | None = None) -> None:
        if not rate > 0:
            raise ValueError(f"the engine rate must be positive, not {rate}")
        self.drone = self.robot = drone
        # the catalog that describes the library's implementations (the aerial one unless a robot kind says)
        reference = described_in or default_catalog()
        if library is None:
            library = default_library()
        # a thin catalog takes the library's own argument descriptions; behaviors nobody implements are marked
        self.catalog = (catalog or default_catalog()).served_by(library.names(), reference)
        if rules:  # a rules file (--rules): checked against the catalog, RuleError with file:line
            self.catalog = self.catalog.with_rules(rules)
        self.clock = clock or SimulatedClock()
        #: the clock's time now: the clock's own method (every period, the event log and the journal ask it)
        self.now: Callable[[], float] = self.clock.now
        self.period = 1.0 / rate
        self.settings = settings or EngineSettings()
        self.memory = BeliefMemory(clock=self.clock)
        self.catalog.declare_vocabulary(self.memory)
        if telemetry is None:
            for name, arity in TELEMETRY_PREDICATES.items():
                if name not in self.catalog.predicates:
                    self.memory.declare(name, arity)
        flight_time = self.catalog.vehicle_limits.get("max_flight_time")
        if vehicle is not None:  # a vehicle profile: its endurance, not the catalog's documented one
            flight_time = vehicle.config.battery_hover_minutes * 60.0
        register_computed(self.memory, drone, self.settings.cruise_speed, obstacles, flight_time)
        # rules in flight are bounded: all the asks of one step together (renewed by tick) may spend so much, an
        # ask that would spend more is refused (the condition asking fails with the reason and the rule's line)
        self.memory.limit_rules(int(self.settings.extra.get("rules_work", RULES_WORK_PER_STEP)), RULES_WORK_WHY,
                                per_step=True)
        self.memory.add_rules(self.catalog.rules)  # derived predicates, asked like stored ones
        self.log = EventLog(self.clock.now)
        self.context = BehaviorContext(drone, self.memory, self.clock.now, self.catalog, self.log, self.settings,
                                       obstacles=obstacles, operator=operator, bus=bus,
                                       output_dir=Path(output_dir) if output_dir is not None else None)
        extra = self.settings.extra
        self.planning = PlanningWorker(self.clock.now, isinstance(self.clock, SimulatedClock),
                                       plan_time=float(extra.get("planning_time", PLAN_TIME)),
                                       wait_limit=float(extra.get("planning_wait", WAIT_LIMIT)))
        self.context.planning = self.planning
        if processes is None:
            processes = default_processes()
        self.library = library
        self.specialist = BehaviorSpecialist(self.catalog, home=lambda: drone.telemetry().home)  # geo: places
        self.resources = ResourceManager(self.catalog, processes, self.log, self.context, capability_grace)
        self.coordinator = BehaviorCoordinator(self.context, library, self.resources, self.specialist)
        if telemetry is None:
            telemetry = TelemetryUpdater(drone, belief_period)
        # self-localization may claim position(self) from the telemetry
        self.context.position_source = getattr(telemetry, "position_source", None)
        self.updaters: list[BeliefUpdater] = [telemetry, *updaters]
        self.context.refresh = lambda: telemetry.refresh(self.memory, self.clock.now())
        memory = self.memory
        self.bridge = MissionBridge(self.clock.now, lambda: memory.changes,
                                    lambda message: self.log.record("mission_polling", detail=message),
                                    self._mission_stalled)
        self._last_refusal: str | None = None  # the last refused request of the mission (behavior: reason)
        self.timers = Timers(self.clock.now)
        #: The vehicle model and the predicates safety rules read (battery_to_home...); the rules' monitors.
        self.vehicle_model = vehicle if vehicle is not None else VehicleModel.of(drone)
        self.safety_predicates = SafetyPredicates(self.memory, self.vehicle_model, self.clock.now,
                                                  lambda: drone.telemetry().velocity)
        self.safety_predicates.register()
        self.log.subscribe(self._mission_clock)
        self.log.subscribe(self._mission_refusals)
        self.safety: SafetyMonitor | None = None
        if self.catalog.safety_rules:  # the monitors' modules are imported for a catalog with safety rules only
            from aeroexec.engine.safety import SafetyMonitor

            self.safety = SafetyMonitor(self, self.catalog.safety_rules, self.vehicle_model, self.safety_predicates)
        #: Called at the end of every tick, on the loop's thread (a behavior tree mission ticks here).
        self.tick_callbacks: list[Callable[[], None]] = []
        #: The operator's commands (pause, resume, abort...), run on this loop's thread (engine/supervision.py).
        self.supervisor = Supervisor(self)
        #: What a tick, and each mission call served, runs within (the flight holds Ctrl-C and SIGTERM in it: what
        #: it records is never cut in two).
        self.period_guard: Callable[[], contextlib.AbstractContextManager[Any]] = contextlib.nullcontext
        self.bridge.guard = lambda: self.period_guard()
        self._started = False
        self._stop = threading.Event()
        self._closed = False
        self._missions: list[threading.Thread] = []
        self._thread: threading.Thread | None = None
        self._lock = threading.RLock()

    # -- the loop ------------------------------------------------------------------------------
    def tick(self) -> None:
        """One period of the engine, at the clock's current time."""
        with self._lock, self.period_guard():
            self.memory.renew_rules()  # the rules' work of a step is bounded (RULES_WORK_PER_STEP)
            if not self._started:
                self._begin()
            now = self.clock.now()
            drone, memory = self.drone, self.memory
            drone.update(now)
            for event in drone.events():  # at the time it happened (the robot's clock is the engine's)
                self.log.record(f"drone_{event.kind}", detail=event.detail, at=min(event.time, now), **event.data)
            for updater in self.updaters:
                updater.tick(memory, now)
            for capability, reason in self.resources.update(now):
                self.coordinator.fail_users(capability, reason)
            if self.safety is not None:  # before the behaviors are monitored: a contingency preempts in this tick
                self.safety.tick(now)
            self.coordinator.tick()
            if self.timers.scheduled:  # (none scheduled: run_due's answer, without its call)
                self.timers.run_due()
            if self.tick_callbacks:
                for callback in list(self.tick_callbacks):
                    try:
                        callback()
                    except Exception:
                        logger.exception("a tick callback failed")

    def _mission_refusals(self, event: Any) -> None:
        """Remember the mission's last refused request until it starts a behavior again."""
        source = getattr(event, "data", {}).get("source")
        if event.kind in ("failed_preconditions", "rejected") and source == "mission":
            self._last_refusal = f"{event.behavior or 'a request'} ({event.detail})" if event.detail else \
                (event.behavior or "a request")
        elif event.kind == "activated" and source == "mission":
            self._last_refusal = None

    def _mission_stalled(self) -> str | None:
        """Why nothing will change what a polling mission waits for: its request was refused, and none of its
        behaviors runs (None: something may still change it)."""
        if self._last_refusal is None:
            return None
        if any(a.source == "mission" and name != "KEEP_HOVERING" for name, a in self.coordinator.active().items()):
            return None
        return f"its request {self._last_refusal} was refused, and none of its behaviors runs"

    def _mission_clock(self, event: Any) -> None:
        """``mission_time(T)`` counts from the mission's start."""
        if event.kind == "mission_started" and self.safety_predicates.mission_started is None:
            self.safety_predicates.mission_started = event.time

    def _begin(self) -> None:
        self._started = True
        self.log.record("engine_started", detail=f"{len(self.catalog)} behaviors, {1 / self.period:g} Hz")
        now = self.clock.now()
        self.drone.update(now)
        for updater in self.updaters:
            updater.tick(self.memory, now)
        self.resources.start_permanent()
        self.coordinator.react()

    def step(self, seconds: float) -> None:
        """Run ticks for ``seconds`` of clock time (simulated clocks jump; tests and scripts)."""
        end = self.clock.now() + seconds - 1e-9
        while self.clock.now() < end and not self._stop.is_set():
            self._one_period(lockstep=True)

    def run_until(self, condition: Callable[[], bool], timeout: float) -> bool:
        """Tick until ``condition()`` holds or ``timeout`` seconds of clock time pass; True if it held."""
        end = self.clock.now() + timeout
        while not condition():
            if self.clock.now() >= end or self._stop.is_set():
                return condition()
            self._one_period(lockstep=True)
        return True

    def _one_period(self, lockstep: bool) -> None:
        self.tick()
        deadline = self.clock.now() + self.period
        simulated = isinstance(self.clock, SimulatedClock)
        if simulated:
            self.bridge.serve(lockstep=True)
            self.planning.wait_due(deadline)  # time does not pass a plan's due time without its answer
        else:
            self.bridge.serve(lockstep=False, until_wall=time.monotonic() + max(0.0, deadline - self.clock.now()))
        self.clock.sleep_until(deadline, self._stop)

    def run(self, mission: Callable[[], Any] | None = None, max_time: float | None = None,
            name: str = "mission") -> None:
        """Run the loop in this thread until the mission ends, ``max_time`` clock seconds pass, or ``stop()``.

        The engine stays usable afterwards (e.g. to land); call :meth:`stop` when done.
        """
        if mission is not None:
            self.start_mission(mission, name)
        end = None if max_time is None else self.clock.now() + max_time
        while not self._stop.is_set():
            if mission is not None and self.bridge.state == DONE:
                break
            if end is not None and self.clock.now() >= end:
                self.log.record("engine_time_limit", detail=f"{max_time:g} s of engine time have passed")
                break
            self._one_period(lockstep=True)
        if mission is not None:
            self.bridge.close()

    # -- missions ------------------------------------------------------------------------------
    def start_mission(self, mission: Callable[[], Any], name: str = "mission") -> threading.Thread:
        """Run ``mission()`` in its own thread; its API calls are served by this engine's loop."""
        from aeroexec.engine import api

        def body() -> None:
            api.bind(self)
            self.bridge.mission_started()
            try:
                try:
                    mission()
                except MissionPreempted as preempted:  # a safety rule's contingency: one of the mission's functions
                    handed = f"{name}: {preempted}; its contingency {preempted.function.__name__} ran"
                    self.bridge.call(lambda: self.log.record("mission_preempted", detail=handed))
                    preempted.function()
                    self.bridge.call(lambda: self.log.record("mission_failed", detail=handed))
                else:
                    self.bridge.call(lambda: self.log.record("mission_completed", detail=name))
            except api.MissionAborted:
                pass
            except Exception as exc:
                where = "" if getattr(exc, "where", "") else api.mission_location(exc)  # RequestRejected says it
                detail = f"{name}{where}: {type(exc).__name__}: {exc}"
                logger.error("the mission failed: %s", detail)
                with contextlib.suppress(api.MissionAborted):
                    self.bridge.call(lambda: self.log.record("mission_failed", detail=detail))
            finally:
                api.unbind()
                self.bridge.mission_finished()

        self.bridge.mission_started()
        self.log.record("mission_started", detail=name)
        thread = threading.Thread(target=body, name=f"aeroexec-{name}", daemon=True)
        thread.start()
        self._missions.append(thread)
        return thread

    # -- threads -------------------------------------------------------------------------------
    def start(self) -> None:
        """Run the loop in a background thread (for embedding); ``stop()`` ends it."""
        if self._thread is not None:
            return
        self._thread = threading.Thread(target=self._loop, name="aeroexec-engine", daemon=True)
        self._thread.start()

    def _loop(self) -> None:
        try:
            while not self._stop.is_set():
                self._one_period(lockstep=False)
        except Exception:
            logger.exception("the engine loop failed")
            raise

    def stop(self, reason: str = "engine stopped") -> None:
        """Stop behaviors, capabilities and the mission; never hangs."""
        if self._closed:
            return
        self._closed = True
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
            self._thread = None
        with self._lock:
            self.coordinator.stop_all(reason)
            self.resources.shutdown()
            self.planning.shutdown()
            self.bridge.close()
            self.log.record("engine_stopped", detail=reason)
        for thread in self._missions:  # a waiting mission unwinds with MissionAborted; give it a moment
            if thread is not threading.current_thread():
                thread.join(timeout=2.0)

    @property
    def stopped(self) -> bool:
        return self._stop.is_set()
