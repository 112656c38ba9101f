"""Supervisory control (paper section 2.1): the operator pauses, resumes and aborts the mission, inhibits a
behavior, answers the robot's question and adds or removes beliefs while the engine runs.

Commands may come from any thread (the live view's keys, the control socket): :meth:`Supervisor.submit`
queues them and the engine executes them on its own thread at the end of a tick, so a command never races
the loop. Every command is recorded as an ``operator_command`` event (``command``, ``argument``, ``origin``,
``ok``).

- pause: the mission stops advancing (a Python mission's next API call blocks; an attached tree stops
  ticking) and the drone holds: every behavior the mission started that is incompatible with
  ``KEEP_HOVERING`` is stopped (INTERRUPTED, "paused by the operator") and ``KEEP_HOVERING`` is activated at
  the higher priority. Other behaviors (perception, self-localization, a question) go on, and so do
  higher-priority reactions (LAND on low battery).
- resume: each behavior the pause stopped is requested again with its arguments and full timeout, as the
  same activation, so the waiting mission call or tree leaf hears its real outcome later, as if nothing had
  happened. The resumed behavior continues what it had done (as PX4's Hold then Resume: a half-done TAKE_OFF
  climbs on to its altitude): its catalog preconditions are checked again only if they still held when it
  was paused, since its own progress may have falsified them (TAKE_OFF is no longer landed). A request the
  situation now refuses ends that call or leaf with its outcome (FAILED_PRECONDITIONS), and the run does
  not end "completed". Time waited with ``wait`` or a tree's Delay/Timeout keeps running while paused.
- abort: the mission stops (its waiting call raises MissionAborted, an attached tree is halted), every
  behavior but LAND is stopped and, when the drone is in the air, LAND is activated at the higher priority.
- suspend: as abort, for a stop the run is to go on from (a battery swap): the run ends ``suspended`` and
  ``aeroexec run --resume`` continues it from where it stopped. Both first record where the mission stopped
  (``mission_stopped``, ``mission_suspended``), before anything is halted.
- the changes of the running mission (skip, jump, insert, modify, delete, replace, load:
  :mod:`aeroexec.engine.supervision.changes`) are checked and made by the flight's :attr:`Supervisor.changes` (a
  bare engine takes a Python mission's skip only); each is recorded as a ``mission_change`` event (``command``,
  ``argument``, ``origin``, ``ok``, ``problems`` when refused, ``edits`` and ``mission`` when taken: see
  :class:`~aeroexec.engine.supervision.changes.ChangeOutcome`) instead of ``operator_command``. ``items``
  lists the mission's items (read only).
"""

from __future__ import annotations

import contextlib
import logging
import threading
from collections import deque
from dataclasses import dataclass, field

from aeroexec.beliefs import BeliefError, UnknownPredicateError, format_term, parse_belief
from aeroexec.drones import LandedState
from aeroexec.engine.catalog.engine_behaviors import LAND
from aeroexec.engine.events import Outcome
from aeroexec.engine.supervision.commands import CHANGES
from aeroexec.engine.supervision.operator import operator_of

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, Protocol

    from aeroexec.engine.supervision.changes import MissionChange
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

logger = logging.getLogger(__name__)

LAND_BEHAVIOR = LAND  # the landing that ends a run
LANDING_TIMEOUT = 180.0  # s of engine time to land after the mission
COMMANDS = ("pause", "resume", "abort", "suspend", "inhibit", "answer", "add", "remove", "status", "query", "items",
            *CHANGES)
READ_ONLY = ("status", "query", "items")  # commands that change nothing: not logged as operator commands
MAX_ANSWERS = 100  # unifications a query returns at most
RUNNING, PAUSED, ABORTED, SUSPENDED = "running", "paused", "aborted", "suspended"


class SupervisedMission(Protocol):
    """A mission the engine ticks (a behavior tree): what pause, resume and abort need of it."""

    def pause(self) -> None: ...

    def resume(self) -> None: ...

    def halt(self, reason: str = "halted") -> None: ...


@dataclass
class CommandResult:
    """What a command did: ``ok``, a sentence for the operator and, for ``status``, the state as data."""

    ok: bool
    message: str
    data: dict[str, Any] = field(default_factory=dict)


class Ticket:
    """A submitted command; :meth:`wait` for its result (None when the engine did not run it in time)."""

    def __init__(self, command: str, argument: str, origin: str) -> None:
        self.command, self.argument, self.origin = command, argument, origin
        self.prepared: Any = None  # what a change needs done before the engine's thread (a file to load, read)
        self.result: CommandResult | None = None
        self._done = threading.Event()

    def finish(self, result: CommandResult) -> None:
        self.result = result
        self._done.set()

    def wait(self, timeout: float) -> CommandResult | None:
        self._done.wait(timeout)
        return self.result


class Supervisor:
    """The operator's commands on one engine (``engine.supervisor``); its queue is served by a tick callback."""

    def __init__(self, engine: Any) -> None:
        self.engine = engine
        self.state = RUNNING
        #: The flight's end has begun (the mission is over): a pause would stop the landing, so it is refused.
        self.flight_ending = False
        self._queue: deque[Ticket] = deque()
        self._lock = threading.Lock()
        self._missions: list[SupervisedMission] = []
        #: (activation, its on_end listeners, whether its preconditions held when paused), in order
        self._suspended: list[tuple[Any, list, bool]] = []
        self._hold_before: tuple[Any, int] | None = None  # the hold behavior active before a pause, its priority
        #: What checks and makes the changes of the running mission (the flight's ``MissionChanges``: ``prepare``,
        #: ``change``, ``items``); a bare engine has none, and takes a Python mission's skip only.
        self.changes: Any = None
        engine.tick_callbacks.append(self.run_pending)

    # -- from any thread ----------------------------------------------------------------------
    def submit(self, command: str, argument: str = "", origin: str = "ctl") -> Ticket:
        """Queue a command for the engine's thread; the ticket tells its result once executed. A mission to load
        is read and checked here, on the caller's thread."""
        if command in ("update", "load"):  # here: a flight whose mission is never changed never imports them
            from aeroexec.engine.supervision.changes import ChangeError, MissionChange, parse_aerostack2_update
        if command == "update":  # Aerostack2's mission update: one of the changes below, or refused as it is
            try:
                command, argument = parse_aerostack2_update(argument)
            except ChangeError as error:
                ticket = Ticket(command, argument, origin)
                ticket.finish(CommandResult(False, str(error)))
                return ticket
        ticket = Ticket(command, argument, origin)
        if command == "load" and self.changes is not None:
            with contextlib.suppress(ChangeError):  # said when executed
                ticket.prepared = self.changes.prepare(MissionChange.parse(command, argument))
        with self._lock:
            self._queue.append(ticket)
        return ticket

    @property
    def paused(self) -> bool:
        return self.state == PAUSED

    @property
    def missions(self) -> tuple[SupervisedMission, ...]:
        return tuple(self._missions)

    # -- on the engine's thread -----------------------------------------------------------------
    def attach(self, mission: SupervisedMission) -> None:
        """A mission ticked by the engine (a tree) that pause, resume and abort must reach."""
        if mission not in self._missions:
            self._missions.append(mission)
            if self.state == PAUSED:
                mission.pause()

    def detach(self, mission: SupervisedMission) -> None:
        if mission in self._missions:
            self._missions.remove(mission)

    def run_pending(self) -> None:
        """Execute the queued commands (the engine calls this at the end of every tick)."""
        if not self._queue:  # none (the usual answer): no lock taken; one queued meanwhile waits a tick
            return
        while True:
            with self._lock:
                if not self._queue:
                    return
                ticket = self._queue.popleft()
            ticket.finish(self.execute(ticket.command, ticket.argument, ticket.origin, ticket.prepared))

    def change(self, change: MissionChange, origin: str = "api") -> Ticket:
        """Queue a change of the running mission (from any thread); the ticket tells whether it was taken."""
        return self.submit(change.command, change.argument, origin)

    def execute(self, command: str, argument: str = "", origin: str = "engine", prepared: Any = None
                ) -> CommandResult:
        """Run one command now (call it on the engine's thread, or while the loop is not running); ``prepared``:
        what :meth:`submit` did for it on the caller's thread."""
        if command in CHANGES:
            return self._change(command, argument, origin, prepared)
        handler = getattr(self, f"_{command}", None) if command in COMMANDS else None
        if handler is None:
            result = CommandResult(False, f"unknown command {command!r}: expected one of {', '.join(COMMANDS)}")
        else:
            try:
                result = handler(argument.strip())
            except Exception as exc:  # a command must never take the engine down
                logger.exception("the operator command %s failed", command)
                result = CommandResult(False, f"{command} failed: {type(exc).__name__}: {exc}")
        if command not in READ_ONLY:
            self.engine.log.record("operator_command", detail=f"{command}{' ' + argument if argument else ''}: "
                                   f"{result.message}", command=command, argument=argument, origin=origin,
                                   ok=result.ok)
        return result

    # -- the commands -------------------------------------------------------------------------------
    def _pause(self, _: str) -> CommandResult:
        hold_behavior = self.engine.settings.hold_behavior
        if self.flight_ending:  # the mission is over: holding the drone would stop its landing (or its return)
            return CommandResult(False, "the mission has ended and the flight is ending (the drone finishes a "
                                        "safety rule's hold or return, then lands): it is not paused; abort lands "
                                        "it now")
        if self.state != RUNNING:
            return CommandResult(False, f"the mission is already {self.state}")
        self.state = PAUSED
        self.engine.bridge.hold(True)
        for mission in self._missions:
            mission.pause()
        coordinator = self.engine.coordinator
        stopped = []
        if hold_behavior in self.engine.catalog.behaviors:
            active = coordinator.active()
            for name in sorted(coordinator.specialist.conflicts(hold_behavior, active),
                               key=lambda n: active[n].order):
                activation = active[name]
                if activation.source != "mission":
                    continue
                listeners = list(activation.on_end)
                activation.on_end.clear()  # the mission does not hear this INTERRUPTED; resume asks again
                self._suspended.append((activation, listeners, coordinator.preconditions_hold(activation)))
                coordinator.stop(name, "paused by the operator")
                stopped.append(name)
            before = coordinator.active().get(hold_behavior)  # already hovering (a reaction): the pause raises it
            self._hold_before = (before, before.priority) if before is not None else None
            hold = coordinator.activate(hold_behavior, priority="higher", source="operator")
            holding = f"; {hold_behavior} holds the drone" if hold.accepted else \
                f"; {hold_behavior} cannot start: {hold.message}"
        else:
            holding = f"; the catalog has no {hold_behavior}: the active behaviors go on"
        what = f"stopped {', '.join(stopped)} until resume, which asks for {'it' if len(stopped) == 1 else 'them'} " \
               f"again" if stopped else "no motion stopped"
        return CommandResult(True, f"mission paused ({what}{holding})")

    def _resume(self, _: str) -> CommandResult:
        hold_behavior = self.engine.settings.hold_behavior
        if self.state != PAUSED:
            return CommandResult(False, "the mission has ended and the flight is ending, nothing is paused"
                                 if self.flight_ending else f"the mission is {self.state}, not paused")
        self.state = RUNNING
        coordinator = self.engine.coordinator
        held = coordinator.active().get(hold_behavior)
        if held is not None and self._hold_before is not None and held is self._hold_before[0]:
            held.priority = self._hold_before[1]  # hovering before the pause: as before, the mission's next may go
        elif held is not None and held.source == "operator":
            coordinator.stop(hold_behavior, "resumed by the operator")
        self._hold_before = None
        again, done, refused = [], [], []
        for activation, listeners, held in self._suspended:
            result = self._request_again(activation, listeners, held)
            if result.accepted:
                again.append(activation.name)
            elif result.outcome is Outcome.GOAL_ACHIEVED:  # the mission hears it achieved: it goes on
                done.append(activation.name)
            else:
                reason = f" ({result.message})" if result.message else ""
                refused.append(f"{activation.name}, {(result.outcome or Outcome.FAILED_PRECONDITIONS).value}{reason}")
        self._suspended.clear()
        for mission in self._missions:
            mission.resume()
        self.engine.bridge.hold(False)
        parts = [f"requested again: {', '.join(again)}"] if again else []
        parts += [f"already achieved, the mission goes on: {', '.join(done)}"] if done else []
        parts += [f"refused now, the mission hears it: {'; '.join(refused)}"] if refused else []
        return CommandResult(True, "mission resumed" + (f" ({'; '.join(parts)})" if parts else ""))

    def _request_again(self, activation: Any, listeners: list, preconditions_held: bool) -> Any:
        told: list[bool] = []

        def relay(outcome: Outcome, message: str, value: Any) -> None:  # once, however the request ends
            if not told:
                told.append(True)
                self._tell(listeners, outcome, message, value)

        activation.on_end[:] = [relay]
        priority = {2: "higher", 1: "deliberative", 0: "lower"}.get(activation.priority, "deliberative")
        result = self.engine.coordinator.activate(activation.name, activation.arguments, priority=priority,
                                                  source=activation.source, timeout=activation.timeout,
                                                  conditions=activation.conditions, resume=activation,
                                                  check_preconditions=preconditions_held)
        if result.accepted and result.activation is not activation and result.activation is not None:
            result.activation.on_end.append(relay)  # merged into an equal recurrent request
        if not result.accepted:
            relay(result.outcome or Outcome.FAILED_PRECONDITIONS, result.message, None)
        return result

    def _abort(self, reason: str) -> CommandResult:
        if self.state in (ABORTED, SUSPENDED):
            return CommandResult(True, f"already {self.state}")
        reason = reason or "aborted by the operator"
        self.engine.log.record("mission_stopped", detail=reason)
        return CommandResult(True, f"mission aborted; {self._stop_mission(ABORTED, reason)}")

    def _suspend(self, reason: str) -> CommandResult:
        if self.state in (ABORTED, SUSPENDED):
            return CommandResult(False, f"the mission is already {self.state}")
        reason = reason or "suspended by the operator"
        self.engine.log.record("mission_suspended", detail=reason)
        landing = self._stop_mission(SUSPENDED, reason)
        return CommandResult(True, f"mission suspended (aeroexec run --resume goes on from here); {landing}")

    def _stop_mission(self, state: str, reason: str) -> str:
        """Stop the mission and every behavior but LAND, and land; what the landing does, in words."""
        self.state = state
        bridge = self.engine.bridge
        bridge.hold(False)
        bridge.close()  # a Python mission's waiting call raises MissionAborted
        for mission in list(self._missions):
            mission.halt(reason)
        for _activation, listeners, _held in self._suspended:
            self._tell(listeners, Outcome.INTERRUPTED, reason)
        self._suspended.clear()
        coordinator = self.engine.coordinator
        for name, _ in sorted(coordinator.active().items(), key=lambda item: -item[1].order):
            if name != LAND_BEHAVIOR:
                coordinator.stop(name, reason)
        return start_landing(self.engine, reason)

    # -- changes of the running mission ------------------------------------------------------------------
    def _change(self, command: str, argument: str, origin: str, prepared: Any = None) -> CommandResult:
        from aeroexec.engine.supervision.changes import make_change

        outcome = make_change(self.engine, self.changes, self.state == ABORTED, command, argument, origin, prepared)
        return CommandResult(outcome.ok, outcome.message, {"problems": outcome.problems} if outcome.problems else {})

    def suspended_requests(self) -> list[Any]:
        """The activations a pause stopped, which resume requests again."""
        return [activation for activation, _, _ in self._suspended]

    def drop_suspended(self, activations: list[Any], outcome: Outcome = Outcome.INTERRUPTED,
                       reason: str = "") -> None:
        """Forget paused requests a change ended: resume does not request them again; their listeners hear
        ``outcome`` (a halted tree leaf no longer listens)."""
        dropped = [entry for entry in self._suspended if entry[0] in activations]
        self._suspended = [entry for entry in self._suspended if entry[0] not in activations]
        for _activation, listeners, _held in dropped:
            self._tell(listeners, outcome, reason)

    def _items(self, _: str) -> CommandResult:
        items = self.changes.items() if self.changes is not None else []
        if not items:
            return CommandResult(False, "the mission has no items to list (a Python program, or none running)")
        return CommandResult(True, f"{len(items)} item{'s' if len(items) != 1 else ''}", {"items": items})

    def _inhibit(self, name: str) -> CommandResult:
        name = name.upper()
        if not name:
            return CommandResult(False, "inhibit needs a behavior name")
        if name not in self.engine.catalog.behaviors:
            return CommandResult(False, f"the behavior {name} does not exist")
        was_active = self.engine.coordinator.inhibit(name, "inhibited by the operator")
        return CommandResult(True, f"{name} {'stopped and ' if was_active else ''}inhibited "
                                   f"(reactions will not start it until it is requested)")

    def _answer(self, text: str) -> CommandResult:
        pending = operator_of(self.engine.context).answer_pending(text)
        if pending is None:
            return CommandResult(False, "no question is waiting for an answer")
        return CommandResult(True, f"answered {pending.question!r} with {pending.value!r}")

    def _add(self, text: str) -> CommandResult:
        memory = self.engine.memory
        try:
            belief = parse_belief(text)
            try:
                added = memory.add(belief)
            except UnknownPredicateError:  # the operator's own predicate, as a mission's AddBelief may
                memory.declare(belief.name, len(belief.args))
                added = memory.add(belief)
        except (BeliefError, ValueError) as error:
            return CommandResult(False, f"cannot add {text!r}: {error}")
        return CommandResult(True, f"added {belief}" if added else f"{belief} was already believed")

    def _remove(self, pattern: str) -> CommandResult:
        try:
            count = self.engine.memory.remove(pattern)
        except (BeliefError, ValueError) as error:
            return CommandResult(False, f"cannot remove {pattern!r}: {error}")
        return CommandResult(True, f"removed {count} belief{'s' if count != 1 else ''} matching {pattern}")

    def _query(self, expression: str) -> CommandResult:
        """Every unification of a belief expression (``object(?X, aruco)``) with the memory, at most MAX_ANSWERS."""
        if not expression:
            return CommandResult(False, "a query needs a belief expression, e.g. object(?X, aruco)")
        try:
            answers = self.engine.memory.query_all(expression)
        except (BeliefError, ValueError) as error:
            return CommandResult(False, f"cannot query {expression!r}: {error}")
        shown = [{str(k): format_term(v) for k, v in answer.items()} for answer in answers[:MAX_ANSWERS]]
        more = f" (the first {MAX_ANSWERS} shown)" if len(answers) > MAX_ANSWERS else ""
        verdict = f"{len(answers)} answer{'s' if len(answers) != 1 else ''}{more}" if answers else "no answer"
        return CommandResult(True, f"{expression}: {verdict}", {"answers": shown, "count": len(answers)})

    def _status(self, _: str) -> CommandResult:
        engine = self.engine
        now = engine.now()
        telemetry = engine.drone.telemetry()
        active = [{"name": a.name, "priority": {2: "higher", 1: "deliberative", 0: "lower"}.get(a.priority),
                   "source": a.source, "elapsed": round(now - a.started_at, 2), "timeout": a.timeout}
                  for a in sorted(engine.coordinator.active().values(), key=lambda a: a.order)]
        questions = [p.question for p in operator_of(engine.context).pending_questions()]
        data = {"state": self.state, "time": round(now, 2), "active": active, "questions": questions,
                "position": [round(v, 2) for v in telemetry.position], "speed": round(telemetry.speed, 2),
                "battery": round(telemetry.battery_percent, 1), "landed_state": telemetry.landed_state.value}
        names = ", ".join(a["name"] for a in active) or "none"
        return CommandResult(True, f"{self.state} at t={now:.1f} s; active: {names}", data)

    @staticmethod
    def _tell(listeners: list, outcome: Outcome, message: str, value: Any = None) -> None:
        for listener in listeners:
            try:
                listener(outcome, message, value)
            except Exception:
                logger.exception("a listener of a paused behavior failed")


def is_flying(engine: Any) -> bool:
    return engine.drone.telemetry().landed_state not in (LandedState.ON_GROUND, LandedState.UNKNOWN)


def start_landing(engine: Any, reason: str) -> str:
    """Activate LAND at the higher priority when the drone is in the air; says what happened."""
    if engine.coordinator.is_active(LAND_BEHAVIOR):
        return "landing"
    if not is_flying(engine):
        return "the drone is on the ground"
    if engine.drone.telemetry().landed_state is LandedState.LANDING:  # e.g. a take-off stopped near the ground
        engine.log.record("landing", detail=f"{reason}; the drone is already landing")
        return "landing"
    engine.log.record("landing", detail=reason)
    result = engine.coordinator.activate(LAND_BEHAVIOR, priority="higher", source="engine")
    return "landing" if result.accepted else f"cannot land: {result.message}"


