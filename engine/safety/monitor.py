"""The safety monitors: every rule watched in the engine's tick, its violations logged and acted on.

Each rule is checked again only when it may have changed (:mod:`aeroexec.engine.safety.schedule`): when a belief
it reads changes, or when the rated values it compares (positions, charge, time) may have moved far enough. A
violation (an ``always`` condition that fails, a ``never`` condition that holds, a ``within`` obligation opened by
its trigger) is logged as ``safety_violated`` with the rule and the beliefs that broke it, and its contingency is
taken (:mod:`aeroexec.engine.safety.contingency`); a ``within`` obligation met in time is ``safety_met``, one not
met by its deadline is a violation too.
"""

from __future__ import annotations

import heapq
import logging
import math
from dataclasses import dataclass, replace
from typing import Any

from aeroexec.beliefs import Conjunction, EvaluationRefused, format_term
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.catalog.contingencies import LAND_CONTINGENCY
from aeroexec.engine.catalog.safety_rules import ALWAYS, WITHIN, SafetyRule
from aeroexec.engine.safety.compliance import SafetyStatus
from aeroexec.engine.safety.contingency import Contingencies
from aeroexec.engine.safety.odometers import Odometers, floats
from aeroexec.engine.safety.predicates import SafetyPredicates
from aeroexec.engine.safety.schedule import TIME, Entry, Plan, Rate, Source, goal_literals

logger = logging.getLogger(__name__)

POSITION, CHARGE = ("position", 2), ("charge", 2)  # beliefs whose new values are scheduled for, not woken by


@dataclass
class _Watch:
    """One rule's monitor: its compiled condition (and trigger), what wakes it, and its state."""

    index: int
    rule: SafetyRule
    condition: Plan | None
    trigger: Plan | None
    reads: frozenset  # predicates whose changes wake it
    generation: int = 0  # moves at every check: the entries an earlier check left are stale
    violated: bool = False
    since: float | None = None  # a within rule: when its obligation opened
    boundary: tuple | None = None  # where the drone was when the rule last held (as believed: floats() reads it)
    violated_at: float = 0.0
    checks: int = 0


def sources(model: VehicleModel, predicates: SafetyPredicates, belief_period: float = 0.1) -> \
        dict[tuple[str, int], Source]:
    """The rates of the beliefs and computed predicates the monitors schedule by."""
    speed = 1.25 * model.max_speed + model.max_climb_rate  # ground speed with a tail wind, and a climb
    telemetry = Rate(per_second=speed, jump=4.0 * model.position_noise + 0.02)  # the telemetry's own position
    rounded = Rate(jump=0.01)  # computed distances are rounded to centimeters

    def home(who: Any) -> Rate:  # the charge a return takes, per meter flown horizontally and vertically
        return Rate(per_meter=((who, "h", predicates.home_cost_horizontal), (who, "z", predicates.home_cost_vertical)),
                    jump=predicates.home_step)

    def braking(who: Any) -> Rate:  # the stopping point moves with the position, and with the velocity's
        return Rate(per_meter=((who, "p", 2.0),), jump=0.5 + model.max_speed * max(belief_period, 0.1))  # changes

    drain = Rate(per_second=1.5 * model.max_drain, jump=1.0)  # charge(battery, N) is floored to whole percent
    return {
        POSITION: Source(point=True, follows=(POSITION,)),
        CHARGE: Source(drain, follows=(CHARGE,)),
        ("mission_time", 1): Source(Rate(per_second=1.0, jump=0.01)),
        ("distance", 3): Source(rounded, through=(0, 1)),
        ("distance_to", 2): Source(telemetry + rounded, through=(0,)),
        ("minimum_distance_to_obstacle", 2): Source(rounded, through=(0,)),
        ("distance_to_obstacle", 2): Source(rounded, through=(0,)),
        ("rally_distance", 2): Source(rounded, through=(0,), mover=lambda who: Rate(per_meter=((who, "h", 1.0),)),
                                      follows=(POSITION,)),
        ("stopping_point", 2): Source(mover=braking, reads=(("velocity", 2),), follows=(POSITION,)),  # a mate's
        # velocity is answered from the fleet's shared table (no belief change per sample): its braking bound covers it
        ("battery_to_home", 2): Source(through=(0,), scale=predicates.home_cost, mover=home, reads=(("wind", 2),),
                                       follows=(POSITION,)),
        ("return_margin", 2): Source(drain, mover=home, reads=(("wind", 2),), follows=(POSITION, CHARGE)),
    }


class SafetyMonitor:
    """Watches ``rules`` on ``engine``'s beliefs; call :meth:`tick` once per engine period."""

    def __init__(self, engine: Any, rules: tuple[SafetyRule, ...], model: VehicleModel,
                 predicates: SafetyPredicates) -> None:
        self.engine, self.memory, self.log = engine, engine.memory, engine.log
        self.rules, self.model, self.predicates = rules, model, predicates
        self.contingencies = Contingencies(engine.coordinator, engine.log, lambda: predicates.position("self"),
                                           self._rally, engine.settings.cruise_speed)
        updaters = getattr(engine, "updaters", None) or [None]
        rated = sources(model, predicates, getattr(updaters[0], "period", 0.1))
        memory = self.memory
        computed = memory.is_computed
        self._watches: list[_Watch] = []
        for index, rule in enumerate(rules):
            condition = Plan.of(rule.condition, rated, computed)
            trigger = Plan.of(rule.trigger, rated, computed) if rule.trigger is not None else None
            scheduled = condition is not None and (rule.trigger is None or trigger is not None)
            for plan in (condition, trigger) if scheduled else ():
                if plan is not None:
                    plan.compile(memory)
            reads: set = set()
            for name, arity in rule.predicates:
                source = rated.get((name, arity))
                if source is not None:
                    reads |= set(source.reads)
                if not scheduled or (name, arity) not in rated:
                    reads.add((name, arity))
            if not scheduled and any(computed(n, a) for n, a in rule.predicates):
                reads.add(("*", 0))  # it reads what a function computes: any change may change it
            self._watches.append(_Watch(index, rule, condition if scheduled else None,
                                        trigger if scheduled else None, frozenset(reads)))
        self._by_signature: dict[tuple, list[int]] = {}
        for watch in self._watches:
            for signature in watch.reads:
                self._by_signature.setdefault(signature, []).append(watch.index)
        self._any = self._by_signature.get(("*", 0), [])
        self._readers: dict[tuple, list[int]] = {}  # every rule reading a predicate, scheduled or not
        for watch in self._watches:
            for signature in watch.rule.predicates:
                self._readers.setdefault(signature, []).append(watch.index)
        self._followers: dict[tuple, list[int]] = {}  # a rated belief -> the rules reading what moves with it: a
        for signature, source in rated.items():  # belief of it that appears or goes (a new fleet mate) wakes them
            for followed in source.follows:
                self._followers.setdefault(followed, []).extend(self._readers.get(signature, []))
        self._followers.setdefault(POSITION, [])
        # the predicates whose changes matter here (the position: the odometers')
        names = {name for name, _ in (*self._by_signature, *self._readers, *self._followers)}
        self._replacing: tuple | None = None
        self._position_woken = sorted({*self._by_signature.get(POSITION, []), *self._any})  # at every move
        self.odometers = Odometers(self._wake, self._live)
        self._woken: set[int] = {w.index for w in self._watches}  # everything is checked at the first tick
        self._due: list[tuple[float, int, int]] = []  # (time, generation, rule)
        self.started = False
        self._in_effect: tuple[str, str, str] | None = None  # the contingency taken last: rule, contingency, action
        #: check every rule at every tick: the reference the schedule must agree with (tests, benches)
        self.every_tick = False
        memory.subscribe(self._changed, None if self._any else names)  # not called for the rest (speed...)

    # -- the tick ---------------------------------------------------------------------------------------------
    def tick(self, now: float) -> None:
        """Check the rules that are due or woken, and act on violations."""
        if self.every_tick:
            self._woken.update(range(len(self._watches)))
        due = self._due
        if not self._woken and not (due and due[0][0] <= now + 1e-9):
            return
        if not self.started:
            self.started = True
            count = len(self.rules)
            self.log.record("safety_watch", detail=f"{count} safety rule{'s' if count != 1 else ''}",
                            rules=[{"rule": r.name, "text": r.text, "contingency": str(r.contingency),
                                    "priority": r.priority, "where": r.where} for r in self.rules])
        watches = self._watches
        while due and due[0][0] <= now + 1e-9:
            _, generation, index = heapq.heappop(due)
            if watches[index].generation == generation:
                self._woken.add(index)
        if not self._woken:
            return
        woken, self._woken = self._woken, set()
        rules = self.rules
        for index in sorted(woken, key=lambda i: (-rules[i].priority, i)):
            self._check(watches[index], now)

    def _wake(self, index: int, generation: int) -> None:
        if self._watches[index].generation == generation:
            self._woken.add(index)

    def _live(self, index: int, generation: int) -> bool:
        return self._watches[index].generation == generation

    def _changed(self, change: Any) -> None:
        belief = change.belief
        name = belief.name
        if name == "position":  # every update of a drone's position: the odometers schedule for it
            if change.kind == "added":
                args = belief.args
                if len(args) == 2 and not self.odometers.moved(args[0], args[1], change.time):
                    self._woken.update(self._followers[POSITION])  # a new fleet mate, or a first position
            elif change.reason != "replaced":  # else its new value follows
                self.odometers.forget(belief.args[0], change.time)
                self._woken.update(self._followers[POSITION])
            if self._position_woken:  # rules that read it and are not scheduled
                self._woken.update(self._position_woken)
            return
        signature = (name, len(belief.args))
        woken = self._woken
        if signature in self._followers:  # a rated belief (the charge): its new value is scheduled for
            if change.kind == "removed":
                if change.reason == "replaced":
                    self._replacing = signature
                    return  # its new value follows
                woken.update(self._followers[signature])
            else:
                replacing, self._replacing = self._replacing == signature, None
                if not replacing:  # a first value
                    woken.update(self._followers[signature])
        indexes = self._by_signature.get(signature)
        if indexes:
            woken.update(indexes)
        if self._any:
            woken.update(self._any)

    # -- one rule ---------------------------------------------------------------------------------------------
    def _check(self, watch: _Watch, now: float) -> None:
        watch.checks += 1
        watch.generation += 1
        rule = watch.rule
        if rule.form == WITHIN:
            entries = self._check_within(watch, now)
        else:
            holds, entries, evidence = self._evaluate(rule.condition, watch.condition, now)
            broken = (not holds) if rule.form == ALWAYS else holds
            if broken and not watch.violated:
                watch.violated = True
                if self.contingencies.active is not rule:  # it held until the tick before (or it would have been
                    watch.boundary = self.odometers.where("self", before=now)  # checked then): where the drone was
                self._violated(watch, now, evidence, "")
            elif not broken and self.contingencies.active is not rule:  # during its own contingency it stays broken
                if watch.violated:
                    watch.violated = False
                    self.log.record("safety_restored", detail=f"{rule.name}: {rule.text} holds again",
                                    rule=rule.name)
                watch.boundary = self.odometers.last("self")
        generation, index = watch.generation, watch.index
        odometers = self.odometers
        if len(entries) > 1:  # any of them wakes it: the first on each odometer is enough
            first: dict = {}
            for key, reading in entries:
                if reading < first.get(key, math.inf):
                    first[key] = reading
            entries = first.items()
        for key, reading in entries:
            if key is TIME:
                due = self._due
                if len(due) > 64 + 4 * len(self._watches):  # stale waits: keep those still standing
                    due[:] = [e for e in due if self._live(e[2], e[1])]
                    heapq.heapify(due)
                heapq.heappush(due, (max(reading, now), generation, index))
            else:
                odometers.wake_at(key, reading, generation, index)

    def _check_within(self, watch: _Watch, now: float) -> list[Entry]:
        """A ``within`` rule: its trigger decides while no obligation is open; then its condition and deadline."""
        rule = watch.rule
        entries: list[Entry] = []
        if watch.since is None:
            fired, entries, trigger_evidence = self._evaluate(rule.trigger, watch.trigger, now)
            if not fired:
                return entries
            holds, more, evidence = self._evaluate(rule.condition, watch.condition, now)
            entries = entries + more
            if holds:
                return entries
            watch.since, watch.violated = now, False
            action = self._act(watch)
            self.log.record("safety_triggered", detail=f"{rule.name}: {rule.trigger.text}; {rule.condition.text} "
                            f"due within {rule.within:g} s; {action}", rule=rule.name, due=round(now + rule.within, 2),
                            beliefs=_shown({**trigger_evidence, **evidence}), contingency=str(rule.contingency),
                            action=action)
        else:
            holds, entries, evidence = self._evaluate(rule.condition, watch.condition, now)
            if holds:
                took = now - watch.since
                self.log.record("safety_met", detail=f"{rule.name}: {rule.condition.text} after {took:.1f} s "
                                f"(within {rule.within:g} s)", rule=rule.name, seconds=round(took, 2))
                watch.since, watch.violated = None, False
                return self._check_within(watch, now)  # the trigger may hold still: what it waits for next
            if not watch.violated and now - watch.since >= rule.within - 1e-9:
                watch.violated = True
                self._violated(watch, now, evidence, f"not within {rule.within:g} s", escalate=True)
        if watch.since is not None and not watch.violated:
            entries = [*entries, (TIME, watch.since + rule.within)]
        return entries

    def _evaluate(self, condition: Conjunction, plan: Plan | None, now: float) -> tuple[bool, list[Entry], dict]:
        memory = self.memory
        try:
            if plan is None:
                found = memory.query(condition)
                evidence = found if found is not None else (memory.query(goal_literals(condition)) or {})
                return found is not None, [], evidence
            return plan.verdict(plan.solve(memory), now, self.odometers.reading)
        except EvaluationRefused as refused:  # rules past the bound of a step: one line, asked again soon
            logger.warning("a safety condition could not be evaluated now: %s: %s", condition.text, refused)
            return False, [(TIME, now + 0.5)], {}
        except Exception:
            logger.exception("a safety condition failed to evaluate: %s", condition.text)
            return False, [(TIME, now + 0.5)], {}

    def _violated(self, watch: _Watch, now: float, evidence: dict, why: str, escalate: bool = False) -> None:
        rule = watch.rule
        watch.violated_at = now
        action = self._act(watch, escalate)
        what = why or (f"{rule.condition.text} no longer holds" if rule.form == ALWAYS
                       else f"{rule.condition.text} holds")
        shown = _shown(evidence)
        beliefs = ", ".join(f"{k} = {v}" for k, v in shown.items())
        self.log.record("safety_violated", detail=f"{rule.name} ({rule.form}): {what}"
                        + (f" [{beliefs}]" if beliefs else "") + f"; {action}",
                        rule=rule.name, form=rule.form, where=rule.where, beliefs=shown,
                        contingency=str(rule.contingency), action=action, priority=rule.priority)

    def _act(self, watch: _Watch, escalate: bool = False) -> str:
        rule = watch.rule
        if escalate and rule.contingency != LAND_CONTINGENCY:  # a deadline missed: land
            rule = replace(rule, contingency=LAND_CONTINGENCY)
        contingencies = self.contingencies
        if not (escalate or contingencies.outranks(rule)):
            return f"the contingency of {contingencies.active.name} stays in effect"
        try:
            action = contingencies.take(rule, floats(watch.boundary))
        except Exception as exc:
            logger.exception("the contingency of %s failed", rule.name)
            action = f"its contingency failed: {type(exc).__name__}: {exc}"
        self._in_effect = (rule.name, str(rule.contingency), action)
        return action

    def _rally(self, here: tuple, home: bool) -> tuple:
        return self.model.home if home else self.predicates.nearest_rally(here)

    # -- compliance -------------------------------------------------------------------------------------------
    def status(self) -> SafetyStatus:
        """The rules violated now, the contingency in effect, the obligations open (for the views)."""
        return SafetyStatus(len(self.rules),
                            tuple((w.rule.name, round(w.violated_at, 2)) for w in self._watches if w.violated),
                            self._in_effect if self.contingencies.active is not None else None,
                            tuple((w.rule.name, round(w.since + w.rule.within, 2)) for w in self._watches
                                  if w.since is not None and not w.violated))

    @property
    def checks(self) -> dict[str, int]:
        """How many times each rule was checked (the monitors' work)."""
        return {w.rule.name: w.checks for w in self._watches}


def _shown(evidence: dict) -> dict[str, str]:
    return {str(k): format_term(v) for k, v in evidence.items() if not str(k).startswith("?#")}


__all__ = ["SafetyMonitor", "sources"]
