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
from dataclasses import dataclass
from typing import Any

from aeroexec.beliefs import Conjunction, format_term
from aeroexec.engine.catalog.safety_rules import ALWAYS, LAND, WITHIN, Contingency, SafetyRule
from aeroexec.engine.safety.contingency import Contingencies
from aeroexec.engine.safety.schedule import Plan, Rate, Source, goal_literals
from aeroexec.engine.safety.vehicle import SafetyPredicates, VehicleModel

logger = logging.getLogger(__name__)

RATED = (("position", 2), ("charge", 2))


@dataclass
class _Watch:
    """One rule's monitor: its compiled condition (and trigger), what wakes it, and its state."""

    index: int
    rule: SafetyRule
    condition: Plan | None
    trigger: Plan | None
    reads: frozenset  # predicates whose changes wake it
    due: float = 0.0
    violated: bool = False
    since: float | None = None  # a within rule: when its obligation opened
    boundary: tuple | None = None  # where the drone was when the rule last held
    checks: int = 0


def sources(model: VehicleModel) -> dict[tuple[str, int], Source]:
    """The rates of the beliefs and computed predicates the monitors schedule by."""
    speed = 1.25 * model.max_speed + model.max_climb_rate  # ground speed with a tail wind, and a climb
    jump = 4.0 * model.position_noise + 0.02  # noise, and the telemetry's rounding to centimeters
    move = Rate(speed, jump)
    drain = Rate(1.5 * model.max_drain, 1.0)  # charge(battery, N) is floored to whole percent
    home = Rate(model.home_rate(1.25 * model.max_speed, model.max_climb_rate), model.home_rate(jump, jump) + 0.1)
    return {
        ("position", 2): Source(move),
        ("charge", 2): Source(drain),
        ("mission_time", 1): Source(Rate(1.0, 0.01)),
        ("distance", 3): Source(through=(0, 1)),
        ("distance_to", 2): Source(move, through=(0,)),
        ("minimum_distance_to_obstacle", 2): Source(through=(0,)),
        ("distance_to_obstacle", 2): Source(through=(0,)),
        ("rally_distance", 2): Source(move),
        ("stopping_point", 2): Source(Rate(2.0 * speed, jump + 0.5)),  # it moves with the speed's changes too
        ("battery_to_home", 2): Source(home, reads=(("wind", 2),)),
        ("return_margin", 2): Source(home + drain, reads=(("wind", 2),)),
    }


class SafetyMonitor:
    """Watches ``rules`` on ``engine``'s beliefs; call :meth:`tick` once per engine period."""

    def __init__(self, engine: Any, rules: tuple[SafetyRule, ...], model: VehicleModel,
                 predicates: SafetyPredicates) -> None:
        self.engine, self.memory, self.log = engine, engine.memory, engine.log
        self.rules, self.model, self.predicates = rules, model, predicates
        self.contingencies = Contingencies(engine.coordinator, engine.log, lambda: predicates.position("self"),
                                           self._rally, engine.settings.cruise_speed)
        rated = sources(model)
        memory = self.memory
        computed = memory.is_computed
        self._watches: list[_Watch] = []
        for index, rule in enumerate(rules):
            condition = Plan.of(rule.condition, rated, computed)
            trigger = Plan.of(rule.trigger, rated, computed) if rule.trigger is not None else None
            scheduled = condition is not None and (rule.trigger is None or trigger is not None)
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
        self._by_signature: dict[tuple, list[_Watch]] = {}
        for watch in self._watches:
            for signature in watch.reads:
                self._by_signature.setdefault(signature, []).append(watch)
        self._any = self._by_signature.get(("*", 0), [])
        self._readers: dict[tuple, list[_Watch]] = {}  # every rule reading a predicate, scheduled or not
        for watch in self._watches:
            for signature in watch.rule.predicates:
                self._readers.setdefault(signature, []).append(watch)
        self._rated = {s for s in rated if s in RATED}
        self._woken: set[int] = {w.index for w in self._watches}  # everything is checked at the first tick
        self._due: list[tuple[float, int]] = []
        self._replacing: Any = None
        self.started = False
        memory.subscribe(self._changed)

    # -- the tick ---------------------------------------------------------------------------------------------
    def tick(self, now: float) -> None:
        """Check the rules that are due or woken, and act on violations."""
        if not self.started:
            self.started = True
            count = len(self.rules)
            self.log.record("safety_watch", detail=f"{count} safety rule{'s' if count != 1 else ''}",
                            rules=[{"rule": r.name, "text": r.text, "contingency": str(r.contingency),
                                    "priority": r.priority, "where": r.where} for r in self.rules])
        due = self._due
        woken = self._woken
        while due and due[0][0] <= now + 1e-9:
            _, index = heapq.heappop(due)
            woken.add(index)
        if not woken:
            return
        self._woken = set()
        for index in sorted(woken, key=lambda i: (-self.rules[i].priority, i)):
            self._check(self._watches[index], now)

    def _changed(self, change: Any) -> None:
        signature = change.belief.signature
        if signature in self._rated:  # a rated belief's new value is scheduled for; one that comes or goes is not
            if change.kind == "removed" and change.reason == "replaced":
                self._replacing = signature
                return
            if change.kind == "added" and self._replacing == signature:
                self._replacing = None
                for watch in self._by_signature.get(signature, ()):  # rules that read it unscheduled
                    self._woken.add(watch.index)
                for watch in self._any:
                    self._woken.add(watch.index)
                return
            for watch in self._readers.get(signature, ()):  # a belief that comes or goes: a new fleet mate
                self._woken.add(watch.index)
        for watch in self._by_signature.get(signature, ()):
            self._woken.add(watch.index)
        for watch in self._any:
            self._woken.add(watch.index)

    # -- one rule ---------------------------------------------------------------------------------------------
    def _check(self, watch: _Watch, now: float) -> None:
        watch.checks += 1
        rule = watch.rule
        holds, seconds, evidence = self._evaluate(rule.condition, watch.condition)
        if rule.form == WITHIN:
            fired, trigger_seconds, trigger_evidence = self._evaluate(rule.trigger, watch.trigger)
            seconds = min(seconds, trigger_seconds)
            self._within(watch, now, fired, holds, {**trigger_evidence, **evidence})
            if watch.since is not None and not watch.violated:
                seconds = min(seconds, watch.since + rule.within - now)
        else:
            broken = (not holds) if rule.form == ALWAYS else holds
            if broken and not watch.violated:
                watch.violated = True
                self._violated(watch, now, evidence, "")
            elif not broken and self.contingencies.active is not rule:  # during its own contingency it stays broken
                if watch.violated:
                    watch.violated = False
                    self.log.record("safety_restored", detail=f"{rule.name}: {rule.text} holds again",
                                    rule=rule.name)
                watch.boundary = self.predicates.position("self")
        if seconds < math.inf:
            heapq.heappush(self._due, (now + max(seconds, 0.0), watch.index))

    def _within(self, watch: _Watch, now: float, fired: bool, holds: bool, evidence: dict) -> None:
        rule = watch.rule
        if watch.since is None:
            if fired and not holds:
                watch.since, watch.violated = now, False
                action = self._act(watch)
                self.log.record("safety_triggered", detail=f"{rule.name}: {rule.trigger.text}; {rule.condition.text} "
                                f"due within {rule.within:g} s; {action}", rule=rule.name,
                                beliefs=_shown(evidence), contingency=str(rule.contingency), action=action)
            return
        if holds:
            took = now - watch.since
            self.log.record("safety_met", detail=f"{rule.name}: {rule.condition.text} after {took:.1f} s "
                            f"(within {rule.within:g} s)", rule=rule.name, seconds=round(took, 2))
            watch.since, watch.violated = None, False
        elif not watch.violated and now - watch.since >= rule.within - 1e-9:
            watch.violated = True
            self._violated(watch, now, evidence, f"not within {rule.within:g} s", escalate=True)

    def _evaluate(self, condition: Conjunction, plan: Plan | None) -> tuple[bool, float, dict]:
        memory = self.memory
        try:
            if plan is None:
                found = memory.query(condition)
                evidence = found if found is not None else (memory.query(goal_literals(condition)) or {})
                return found is not None, math.inf, evidence
            return plan.verdict(memory.query_all(plan.goals))
        except Exception:
            logger.exception("a safety condition failed to evaluate: %s", condition.text)
            return False, 0.5, {}

    def _violated(self, watch: _Watch, now: float, evidence: dict, why: str, escalate: bool = False) -> None:
        rule = watch.rule
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
        if escalate and rule.contingency.kind != LAND:  # a deadline missed: land
            from dataclasses import replace

            rule = replace(rule, contingency=Contingency(LAND))
        contingencies = self.contingencies
        if not (escalate or contingencies.outranks(rule)):
            return f"the contingency of {contingencies.active.name} stays in effect"
        try:
            return contingencies.take(rule, watch.boundary)
        except Exception as exc:
            logger.exception("the contingency of %s failed", rule.name)
            return f"its contingency failed: {type(exc).__name__}: {exc}"

    def _rally(self, here: tuple, home: bool) -> tuple:
        return self.model.home if home else self.predicates.nearest_rally(here)

    # -- compliance -------------------------------------------------------------------------------------------
    @property
    def checks(self) -> dict[str, int]:
        """How many times each rule was checked (the monitors' work)."""
        return {w.rule.name: w.checks for w in self._watches}


def _shown(evidence: dict) -> dict[str, str]:
    return {str(k): format_term(v) for k, v in evidence.items() if not str(k).startswith("?#")}


__all__ = ["SafetyMonitor", "sources"]
