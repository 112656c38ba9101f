"""Contingencies: what the engine does when a safety rule is broken, through the behavior coordinator at the
reactive-higher priority of the paper (it stops the mission's motion, and the mission cannot start it again).

``hold`` flies back to where the rule last held (the boundary) and hovers; ``return`` flies to the nearest of
home and the rally points (home for ``return home``) at the altitude it is at, and lands; ``land`` lands where
the drone is; ``subtree ID`` / ``call FUNCTION`` hand the mission over to its own contingency (a handler the
flight registers; what the mission was running is stopped: a subtree's tree is halted, a called function's mission
has its behaviors stopped). While a hold, return or land is in effect the mission's requests are refused, naming
the rule; a rule of higher priority may take over from one of lower.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any

from aeroexec.engine.catalog.safety_rules import CALL, HOLD, LAND, RETURN, SUBTREE, SafetyRule
from aeroexec.engine.events import Outcome

logger = logging.getLogger(__name__)

GO, HOVER, DESCEND = "GO_TO_POINT", "KEEP_HOVERING", "LAND"
_SEVERITY = {LAND: 3, RETURN: 2, HOLD: 1, SUBTREE: 0, CALL: 0}  # ties of priority: the more conservative wins


class Contingencies:
    """Takes contingencies on the engine's coordinator; ``handlers`` serve ``subtree`` and ``call``."""

    def __init__(self, coordinator: Any, log: Any, position: Callable[[], tuple | None],
                 rally: Callable[[tuple, bool], tuple], cruise_speed: float) -> None:
        self.coordinator, self.log = coordinator, log
        self.position, self.rally, self.cruise_speed = position, rally, cruise_speed
        self.handlers: dict[str, Callable[[str, SafetyRule], bool]] = {}
        self.active: SafetyRule | None = None  # the rule whose contingency is in effect

    def outranks(self, rule: SafetyRule) -> bool:
        """Whether ``rule``'s contingency takes over from the one in effect (if any)."""
        current = self.active
        if current is None:
            return True
        return (rule.priority, _SEVERITY[rule.contingency.kind]) > (current.priority,
                                                                     _SEVERITY[current.contingency.kind])

    def take(self, rule: SafetyRule, boundary: tuple | None = None) -> str:
        """Take ``rule``'s contingency; what was done, in words."""
        kind = rule.contingency.kind
        self.active = rule
        if kind in (SUBTREE, CALL):
            handler = self.handlers.get(kind)
            if handler is not None and handler(rule.contingency.target, rule):
                if kind == CALL:  # what the mission waited on (a WAIT, a flight) ends: its function takes over
                    self._stop_mission(f"safety rule {rule.name}: {rule.contingency}")
                return f"handed over to {rule.contingency}"
            self.log.record("safety_contingency", detail=f"{rule.name}: nothing serves {rule.contingency}; landing",
                            rule=rule.name)
            kind = LAND
        self.coordinator.preempted_by = f"safety rule {rule.name} ({rule.contingency})"
        here = self.position()
        if kind == LAND or here is None:
            self._activate(rule, DESCEND, {})
            return "landing where it is"
        if kind == HOLD:
            target = boundary if boundary is not None else here
            self._go(rule, target, then=HOVER)
            return f"holding at {_fmt(target)}"
        target = self.rally(here, rule.contingency.home)
        point = (target[0], target[1], here[2])
        self._go(rule, point, then=DESCEND)
        return f"returning to {_fmt(point)} to land"

    def _stop_mission(self, reason: str) -> None:
        """Stop the behaviors the mission started (a subtree's hand-over halts its tree, which stops them)."""
        for name, activation in sorted(self.coordinator.active().items(), key=lambda item: -item[1].order):
            if activation.source == "mission":
                self.coordinator.stop(name, reason)

    def _go(self, rule: SafetyRule, point: tuple, then: str) -> None:
        here = self.position() or point
        timeout = 30.0 + 2.0 * math.dist(here, point) / max(self.cruise_speed, 0.5)

        def arrived(outcome: Outcome, message: str, result: Any) -> None:
            if self.active is not rule:
                return  # another rule took over
            if outcome is Outcome.GOAL_ACHIEVED or then == DESCEND:
                self._activate(rule, then, {})  # a return that could not arrive lands where it is
            elif outcome is not Outcome.INTERRUPTED:
                self._activate(rule, HOVER, {})

        if math.dist(here, point) <= 0.3:
            self._activate(rule, then, {})
            return
        self._activate(rule, GO, {"COORDINATES": [round(v, 2) for v in point]}, timeout, arrived)

    def _activate(self, rule: SafetyRule, behavior: str, arguments: dict, timeout: float | None = None,
                  on_end: Callable | None = None) -> None:
        result = self.coordinator.activate(behavior, arguments, priority="higher", source="safety", timeout=timeout,
                                           on_end=on_end, check_preconditions=False)
        if not result.accepted and behavior == GO and result.outcome is Outcome.GOAL_ACHIEVED and on_end is not None:
            on_end(Outcome.GOAL_ACHIEVED, result.message, None)  # already there: what comes after
            return
        if not result.accepted and behavior != DESCEND:
            logger.warning("safety rule %s: %s refused (%s); landing", rule.name, behavior, result.message)
            self.coordinator.activate(DESCEND, {}, priority="higher", source="safety", check_preconditions=False)


def _fmt(point: tuple) -> str:
    return "(" + ", ".join(f"{v:.1f}" for v in point) + ")"


__all__ = ["Contingencies"]
