"""The behavior coordinator (paper section 4.2, Algorithms 4 and 5): activates, monitors and stops behaviors.

Priorities: reactive-higher > deliberative > reactive-lower, ties broken by
recency. An activation checks the situation (the catalog's preconditions and
the behavior's own checks), then group consistency through the specialist;
incompatible active behaviors of lower or equal priority are stopped, one of
higher priority makes the request fail. When a behavior ends, the reactive rules
whose conditions hold are activated if compatible (Algorithm 5); rules are also
evaluated when their condition becomes true.
"""

from __future__ import annotations

import logging
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from aeroexec.beliefs import EvaluationRefused
from aeroexec.engine.catalog import BehaviorSpecialist
from aeroexec.engine.catalog.descriptors import DELIBERATIVE, GOAL_BASED, HIGHER, LOWER, RECURRENT, ReactiveRule
from aeroexec.engine.catalog.world_check import clearance_note
from aeroexec.engine.errors import UNSUPPORTED, SpecificationError, unsupported_message
from aeroexec.engine.events import (
    Outcome,
    achieved_goal_message,
    failed_preconditions_message,
    time_out_message,
    wrong_progress_message,
)
from aeroexec.engine.execution.explain import explain_failure
from aeroexec.engine.execution.process import BehaviorContext, BehaviorLibrary, BehaviorProcess
from aeroexec.engine.execution.reactive import RuleWatch
from aeroexec.engine.execution.resources import ResourceError, ResourceManager

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.engine.execution.activation import ActivationConditions

logger = logging.getLogger(__name__)

#: Priority of an activation request: reactive-higher > deliberative > reactive-lower.
PRIORITY = {HIGHER: 2, "deliberative": 1, LOWER: 0}
TIMEOUT_MARGIN = 1.5  # a behavior's timeout is its catalog timeout plus this many times its expected duration
DELIBERATION = PRIORITY["deliberative"]
_ORDER = operator.attrgetter("order")  # activations in the order they were activated


@dataclass(eq=False)
class Activation:
    """An active behavior: its process, who asked for it, at which priority and when."""

    name: str
    arguments: dict[str, Any]
    process: BehaviorProcess
    priority: int
    order: int  # recency: a larger number is a more recent request
    source: str  # "mission", "reactive", "operator"
    started_at: float
    timeout: float | None
    conditions: ActivationConditions | None = None
    requested_at: float = 0.0
    running: bool = False  # False while a recurrent behavior waits for its activation conditions
    on_end: list[Callable[[Outcome, str, Any], None]] = field(default_factory=list)

    @property
    def category(self) -> str:
        return self.process.descriptor.category


@dataclass(frozen=True, slots=True)
class ActivationResult:
    """The answer to an activation request: accepted, or why not (FAILED_PRECONDITIONS, or goal already achieved)."""

    accepted: bool
    outcome: Outcome | None = None
    message: str = ""
    activation: Activation | None = None


class BehaviorCoordinator:
    """Keeps the set of active behaviors consistent with the situation, the catalog and the priorities."""

    def __init__(self, context: BehaviorContext, library: BehaviorLibrary, resources: ResourceManager,
                 specialist: BehaviorSpecialist | None = None) -> None:
        self.context = context
        self.catalog = context.catalog
        self.library = library
        self.resources = resources
        self.specialist = specialist or BehaviorSpecialist(self.catalog)
        self.log = context.log
        self._active: dict[str, Activation] = {}
        self._ordered: list[Activation] | None = None  # the active ones in activation order (None: to be sorted)
        self._order = 0
        self._react = False  # Algorithm 5 is due
        self._inhibited: set[str] = set()
        self._rules = RuleWatch(self.catalog.reactive_rules, context.memory)  # which rules to evaluate, and when
        #: set by a safety contingency in effect (engine/safety): the mission's requests are refused, saying why
        self.preempted_by: str | None = None

    # -- queries --------------------------------------------------------------------------
    def is_active(self, name: str) -> bool:
        return name in self._active

    def active(self) -> dict[str, Activation]:
        return dict(self._active)

    # -- Algorithm 4 ----------------------------------------------------------------------
    def activate(self, name: str, arguments: Mapping[str, Any] | None = None, *, priority: str = "deliberative",
                 source: str = "mission", timeout: float | None = None,
                 conditions: ActivationConditions | None = None,
                 on_end: Callable[[Outcome, str, Any], None] | None = None,
                 resume: Activation | None = None, check_preconditions: bool = True) -> ActivationResult:
        """Request ``name`` active (Algorithm 4). ``on_end(outcome, message, result)`` is told when it finishes.
        ``resume``: an ended activation to reuse (with its listeners) for this request (the operator's resume);
        its process hands over to the new one. ``check_preconditions=False`` skips the catalog's preconditions
        (a resumed request whose own progress falsified them, as a half-done TAKE_OFF is no longer landed)."""
        now = self.context.now()
        arguments = dict(arguments or {})
        try:
            arguments = self.specialist.resolve_arguments(name, arguments)
        except SpecificationError as error:
            return self._refuse(name, error.kind, error.message, source)
        cls = self.library.get(name)
        if cls is None:
            return self._refuse(name, UNSUPPORTED, unsupported_message(name), source)
        if self.preempted_by is not None and source == "mission":
            message = f"{failed_preconditions_message(name)} The {self.preempted_by} has taken over the drone."
            self.log.record("failed_preconditions", name, message, source=source)
            return ActivationResult(False, Outcome.FAILED_PRECONDITIONS, message)
        level = PRIORITY[priority]
        if source != "reactive":
            self._inhibited.discard(name)  # asking for it again lifts an inhibition
        previous = self._active.get(name)
        if previous is not None and previous.arguments == arguments and previous.category == RECURRENT:
            previous.priority, previous.order = max(previous.priority, level), self._next_order()
            self._ordered = None
            if on_end:
                previous.on_end.append(on_end)
            return ActivationResult(True, activation=previous)
        process = cls(self.catalog.behaviors[name], arguments, self.context)
        if resume is not None:
            process.resume_from(resume.process)
        self.context.refresh()  # decide on the drone's state now, not as of the last belief update
        situation = self._check_situation(process, check_preconditions)  # step 1
        if situation is not None:
            outcome, message = situation
            self.log.record(outcome.value if outcome is Outcome.GOAL_ACHIEVED else "failed_preconditions", name,
                            message, source=source)
            return ActivationResult(False, outcome, message)
        clashing = self.specialist.conflicts(name, self._active)
        conflicts = [a for other, a in self._active.items() if other in clashing]  # in activation order
        higher = [a for a in conflicts if a.priority > level]
        if higher:  # step 6: an incompatible active behavior of higher priority
            blocker = max(higher, key=lambda a: a.priority)
            message = (f"{failed_preconditions_message(name)} The active behavior {blocker.name} has a higher "
                       f"priority and is incompatible with it.")
            self.log.record("rejected", name, message, source=source, blocker=blocker.name)
            return ActivationResult(False, Outcome.FAILED_PRECONDITIONS, message)
        if previous is not None:
            conflicts.append(previous)
        for other in conflicts:  # step 10: stop the incompatible ones of lower or equal priority
            self._finish(other, Outcome.INTERRUPTED, f"stopped for {name} ({source})")
        return self._start(process, arguments, level, source, timeout, conditions, on_end, now, resume)

    def _start(self, process: BehaviorProcess, arguments: dict[str, Any], level: int, source: str,
               timeout: float | None, conditions: ActivationConditions | None,
               on_end: Callable | None, now: float, resume: Activation | None = None) -> ActivationResult:
        name = process.name
        ready = conditions is None or conditions.hold(self.context, now)
        if ready:
            try:  # Algorithm 1, step 1: activate the resources
                self.resources.acquire(name, process.descriptor.capabilities)
            except ResourceError as error:
                message = f"{failed_preconditions_message(name)} Its resources cannot be activated: {error}"
                self.log.record("failed_preconditions", name, message, source=source)
                return ActivationResult(False, Outcome.FAILED_PRECONDITIONS, message)
        if timeout is None and process.descriptor.timeout is not None:
            timeout = process.descriptor.timeout
            needed = process.expected_duration()  # the catalog's timeout, on top of what the work asked takes
            if needed is not None and needed > 0:
                timeout = round(timeout + TIMEOUT_MARGIN * needed, 1)
        if resume is not None:  # the same request again: whoever waits on it hears how this one ends
            activation = resume
            activation.process, activation.priority, activation.order = process, level, self._next_order()
            activation.source, activation.started_at, activation.requested_at = source, now, now
            activation.timeout, activation.conditions, activation.running = timeout, conditions, False
            activation.on_end.extend([on_end] if on_end else [])
        else:
            activation = Activation(name, arguments, process, level, self._next_order(), source, now, timeout,
                                    conditions, now, on_end=[on_end] if on_end else [])
        self._active[name] = activation
        self._ordered = None
        self.log.record("activated", name, _describe_arguments(arguments), source=source,
                        priority=_priority_name(level), timeout=timeout, arguments=dict(arguments),
                        waiting=None if ready else str(conditions))
        if ready and not self._begin(activation):
            return ActivationResult(False, Outcome.WRONG_PROGRESS, process.reason)
        self._react = True
        return ActivationResult(True, activation=activation)

    def _begin_when_ready(self, activation: Activation) -> None:
        """A behavior that waited for its activation conditions: its resources, then its start."""
        if not activation.conditions.hold(self.context, activation.requested_at):
            return
        try:
            self.resources.acquire(activation.name, activation.process.descriptor.capabilities)
        except ResourceError as error:
            self._finish(activation, Outcome.WRONG_PROGRESS,
                         f"{wrong_progress_message(activation.name)} (its resources cannot be activated: {error})")
            return
        self.log.record("started", activation.name, "its activation conditions hold")
        self._begin(activation)

    def _begin(self, activation: Activation) -> bool:
        """Algorithm 1, steps 2-5: start the timer and the behavior's own start."""
        process = activation.process
        process.started_at = activation.started_at = self.context.now()
        try:
            process.on_start()
        except Exception as exc:
            logger.exception("behavior %s failed to start", activation.name)
            process.reason = process.reason or f"it raised {type(exc).__name__}: {exc}"
            self._finish(activation, Outcome.WRONG_PROGRESS, process.reason)
            return False
        activation.running = True
        return True

    def preconditions_hold(self, activation: Activation) -> bool:
        """Whether the catalog's preconditions of an active behavior hold now (with its arguments)."""
        preconditions = activation.process.descriptor.preconditions
        if preconditions is None:
            return True
        bindings = {f"?{key}": value for key, value in activation.process.arguments.items()}
        bindings.update(activation.process.bindings)
        try:
            return self.context.memory.query(preconditions, bindings) is not None
        except EvaluationRefused as refused:  # rules past the bound of a step: they do not hold now
            logger.warning("the preconditions of %s: %s", activation.process.name, refused)
            return False

    def _check_situation(self, process: BehaviorProcess, check_preconditions: bool = True
                         ) -> tuple[Outcome, str] | None:
        name = process.name
        try:
            process.prepare()
            preconditions = process.descriptor.preconditions if check_preconditions else None
            if preconditions is not None:
                bindings = {f"?{key}": value for key, value in process.arguments.items()}
                bindings.update(process.bindings)
                if self.context.memory.query(preconditions, bindings) is None:
                    why = explain_failure(self.context.memory, preconditions, bindings)
                    note = clearance_note(process.descriptor, bindings, self.context.obstacles)
                    why += f" ({note})" if note else ""
                    return Outcome.FAILED_PRECONDITIONS, f"{failed_preconditions_message(name)} {why}"
            situation = process.check_situation()
        except EvaluationRefused as refused:  # preconditions over rules past the bound of a step: the reason, no trace
            return Outcome.FAILED_PRECONDITIONS, f"{failed_preconditions_message(name)} {refused}"
        except Exception as exc:
            logger.exception("the situation check of %s failed", name)
            return Outcome.FAILED_PRECONDITIONS, (f"{failed_preconditions_message(name)} Its situation check "
                                                  f"raised {type(exc).__name__}: {exc}")
        if situation is None:
            return None
        if situation.outcome is Outcome.GOAL_ACHIEVED:
            return Outcome.GOAL_ACHIEVED, f"{achieved_goal_message(name)} ({situation.reason})"
        return situation.outcome, f"{failed_preconditions_message(name)} {situation.reason}"

    # -- stopping -----------------------------------------------------------------------
    def inhibit(self, name: str, reason: str = "inhibited") -> bool:
        """Stop ``name`` with INTERRUPTED and keep reactive rules from starting it again until requested."""
        self._inhibited.add(name)
        return self.stop(name, reason)

    def stop(self, name: str, reason: str = "stopped") -> bool:
        """Stop ``name`` with INTERRUPTED; reactive rules may start it again (a halted tree node, for example)."""
        activation = self._active.get(name)
        if activation is None:
            return False
        self._finish(activation, Outcome.INTERRUPTED, reason)
        return True

    def stop_all(self, reason: str) -> None:
        for activation in sorted(self._active.values(), key=lambda a: -a.order):
            self._finish(activation, Outcome.INTERRUPTED, reason)

    # -- Algorithm 2 per tick, Algorithm 5 on events -------------------------------------------
    def tick(self) -> None:
        """Monitor every active behavior once, then run the reactive rules if anything changed."""
        now = self.context.clock()  # the context's now(), one call fewer (every period)
        ordered = self._ordered
        if ordered is None:  # sorted again only when a behavior started or ended (not every tick)
            ordered = self._ordered = sorted(self._active.values(), key=_ORDER)
        for activation in ordered:
            if self._active.get(activation.name) is not activation:
                continue  # finished while another one was monitored
            if not activation.running:
                self._begin_when_ready(activation)
                continue
            process = activation.process  # Algorithm 2's monitoring, inline (every active behavior, every tick)
            try:
                outcome = process.on_run()
            except Exception as exc:
                logger.exception("behavior %s raised", activation.name)
                process.reason = f"it raised {type(exc).__name__}: {exc}"
                outcome = Outcome.WRONG_PROGRESS
            if outcome is None and (activation.timeout is None or now - activation.started_at < activation.timeout):
                continue  # goes on (the usual answer): what _judged would say, without its call
            outcome, message = self._judged(activation, outcome, now)
            if outcome is not None:
                self._finish(activation, outcome, message)
        if self._react or self._rules.due:
            self.react()

    def _judged(self, activation: Activation, outcome: Outcome | None, now: float) -> tuple[Outcome | None, str]:
        """What ends ``activation`` after its process's ``on_run`` answered ``outcome`` at ``now`` (None: it goes
        on), and the message saying why."""
        process = activation.process
        if outcome is Outcome.WRONG_PROGRESS:
            reason = f" ({process.reason})" if process.reason else ""
            return outcome, wrong_progress_message(activation.name) + reason
        if outcome is Outcome.FAILED_PRECONDITIONS:  # found out while running (a plan that came back empty)
            return outcome, f"{failed_preconditions_message(activation.name)} {process.reason}".rstrip()
        if outcome is Outcome.GOAL_ACHIEVED and activation.category in (GOAL_BASED, DELIBERATIVE):
            return outcome, ""
        if activation.timeout is not None and now - activation.started_at >= activation.timeout:
            return Outcome.TIME_OUT, time_out_message(activation.name, activation.timeout)
        return None, ""

    def fail_users(self, capability: str, reason: str) -> None:
        """Stop with WRONG_PROGRESS every behavior that needs a capability that failed."""
        for activation in list(self._active.values()):
            if capability in activation.process.descriptor.capabilities:
                self._finish(activation, Outcome.WRONG_PROGRESS,
                             f"{wrong_progress_message(activation.name)} ({reason})")

    def _finish(self, activation: Activation, outcome: Outcome, message: str) -> None:
        """Algorithm 3 and the event: stop the process, release resources, tell who waits."""
        if self._active.get(activation.name) is not activation:
            return
        del self._active[activation.name]
        self._ordered = None
        process = activation.process
        if activation.running:
            try:
                process.on_stop(outcome)
            except Exception:
                logger.exception("behavior %s failed to stop cleanly", activation.name)
        self.resources.release(activation.name, self.context.now())
        self.log.record(outcome.value, activation.name, message, source=activation.source,
                        result=process.result if activation.category == DELIBERATIVE else None)
        for callback in activation.on_end:
            try:
                callback(outcome, message, process.result)
            except Exception:
                logger.exception("a listener of %s failed", activation.name)
        self._react = True

    def react(self) -> None:
        """Algorithm 5: activate the reactive rules whose conditions hold and that fit with the active behaviors.

        A rule is considered after a behavior event, and whenever its condition becomes true.
        """
        event = self._react
        self._react = False
        if event:
            self.context.refresh()
        changed = self._rules.take_changes()
        for index, rule in enumerate(self.catalog.reactive_rules):
            holds, rising = self._rules.evaluate(index, rule, event, changed, self._holds)
            if not holds or not (event or rising) or rule.behavior in self._active:
                continue
            if rule.behavior in self._inhibited or rule.behavior not in self.library:
                continue
            if rule.priority == LOWER and self.specialist.conflicts(rule.behavior, self._active):
                continue  # lines 6-10: a lower-priority reaction never displaces what is active
            result = self.activate(rule.behavior, rule.arguments, priority=rule.priority, source="reactive")
            if result.accepted:
                self.log.record("reactive", rule.behavior, f"activated by reaction ({rule.priority} priority)"
                                + (f": {rule.condition_text}" if rule.condition is not None else ""))

    def _holds(self, rule: ReactiveRule) -> bool:
        if rule.condition is None:
            return True
        try:
            return self.context.memory.query(rule.condition) is not None
        except EvaluationRefused as refused:  # rules past the bound of a step: one line, not a traceback
            logger.warning("the condition of the reactive rule for %s: %s", rule.behavior, refused)
            return False
        except Exception:
            logger.exception("the condition of the reactive rule for %s failed", rule.behavior)
            return False

    def _next_order(self) -> int:
        self._order += 1
        return self._order

    def _refuse(self, name: str, kind: str, message: str, source: str) -> ActivationResult:
        self.log.record("rejected", name, message, error=kind, source=source)
        return ActivationResult(False, Outcome.FAILED_PRECONDITIONS, message)


def _describe_arguments(arguments: Mapping[str, Any]) -> str:
    return ", ".join(f"{k}={v}" for k, v in arguments.items())


def _priority_name(level: int) -> str:
    return {2: "higher", 1: "deliberative", 0: "lower"}[level]
