"""Contingencies taken: what the engine does when a safety rule is broken, through the behavior coordinator at the
reactive-higher priority of the paper (it stops the mission's motion, and the mission cannot start it again).

What each contingency does is its descriptor's (:mod:`aeroexec.engine.catalog.contingencies`: ``hold`` flies back
to where the rule last held and hovers, ``return`` flies to the nearest of home and the rally points and lands,
``land`` lands, ``subtree ID`` / ``call FUNCTION`` hand the mission over to its own contingency, a plugin's what
it says); :class:`Contingencies` chooses which one is in effect (a rule of higher priority, or of the same
priority and a more severe contingency, takes over) and gives it the means to act (:class:`Actions`): the
coordinator, where the drone is, the rally points, the mission's handlers. While a contingency that took the drone
over is in effect the mission's requests are refused, naming the rule.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import Any

from aeroexec.engine.catalog.contingencies import LAND_CONTINGENCY, ContingencyKind, contingency_kinds
from aeroexec.engine.catalog.engine_behaviors import GO_TO_POINT, KEEP_HOVERING, LAND
from aeroexec.engine.catalog.safety_rules import SafetyRule
from aeroexec.engine.events import Outcome

logger = logging.getLogger(__name__)


class Contingencies:
    """Takes contingencies on the engine's coordinator; ``handlers`` serve the mission's own (``subtree``,
    ``call``: the flight registers them)."""

    def __init__(self, coordinator: Any, log: Any, position: Callable[[], tuple | None],
                 rally: Callable[[tuple, bool], tuple], cruise_speed: float) -> None:
        self.coordinator, self.log = coordinator, log
        self.position, self.rally, self.cruise_speed = position, rally, cruise_speed
        catalog = getattr(coordinator, "catalog", None)
        #: The catalog's behavior for each the engine requests (the one whose ``motion:`` is the same as the aerial
        #: catalog's of that name, when the catalog has no behavior of that name).
        self.named = {word: catalog.with_motion(motion, word) if catalog is not None else word
                      for word, motion in ((GO_TO_POINT, "fly_to"), (LAND, "descend"), (KEEP_HOVERING, "hover"))}
        self.handlers: dict[str, Callable[[str, SafetyRule], bool]] = {}
        self.active: SafetyRule | None = None  # the rule whose contingency is in effect
        #: Where the contingency in effect flies the drone to (a hold's boundary, a return's rally point), if it does.
        self.target: tuple | None = None
        self._boundary: tuple | None = None

    def take_again(self) -> str:
        """The contingency in effect taken again, from where the drone is now (a drone that crossed a hold's boundary
        at speed stops metres past it: flown back)."""
        assert self.active is not None
        return self.take(self.active, self._boundary)

    def outranks(self, rule: SafetyRule) -> bool:
        """Whether ``rule``'s contingency takes over from the one in effect (if any)."""
        current = self.active
        if current is None:
            return True
        return (rule.priority, _kind(rule).severity) > (current.priority, _kind(current).severity)

    def take(self, rule: SafetyRule, boundary: tuple | None = None) -> str:
        """Take ``rule``'s contingency; what was done, in words. One that fails (a plugin's mistake) lands the
        drone where it is, and says why."""
        self.active, self.target, self._boundary = rule, None, boundary
        actions = Actions(self, rule, boundary)
        try:
            return _kind(rule).act(rule.contingency, actions)
        except Exception as exc:
            logger.exception("the contingency of safety rule %s (%s) failed", rule.name, rule.contingency)
            actions.take_over()
            return f"its contingency failed ({type(exc).__name__}: {exc}); {actions.land()}"


class Actions:
    """What a contingency may do for ``rule`` (the :class:`~aeroexec.engine.catalog.contingencies.ContingencyActions`
    its descriptor acts through)."""

    def __init__(self, contingencies: Contingencies, rule: SafetyRule, boundary: tuple | None) -> None:
        self._of, self.rule, self.boundary = contingencies, rule, boundary

    def here(self) -> tuple | None:
        return self._of.position()

    def rally(self, here: tuple, home: bool) -> tuple:
        return self._of.rally(here, home)

    def take_over(self) -> None:
        self._of.coordinator.preempted_by = f"safety rule {self.rule.name} ({self.rule.contingency})"

    def land(self) -> str:
        self.activate(LAND)
        return "landing where it is"

    def record(self, detail: str) -> None:
        self._of.log.record("safety_contingency", detail=detail, rule=self.rule.name)

    def hand_over(self, kind: str, target: str) -> bool:
        handler = self._of.handlers.get(kind)
        return handler is not None and bool(handler(target, self.rule))

    def stop_mission(self) -> None:
        """Stop the behaviors the mission started (a subtree's hand-over halts its tree, which stops them)."""
        coordinator = self._of.coordinator
        reason = f"safety rule {self.rule.name}: {self.rule.contingency}"
        for name, activation in sorted(coordinator.active().items(), key=lambda item: -item[1].order):
            if activation.source == "mission":
                coordinator.stop(name, reason)

    def fly_to(self, point: tuple, then: str) -> None:
        of, rule = self._of, self.rule
        of.target = tuple(point)
        here = of.position() or point
        timeout = 30.0 + 2.0 * math.dist(here, point) / max(of.cruise_speed, 0.5)

        def arrived(outcome: Outcome, message: str, result: Any) -> None:
            if of.active is not rule:
                return  # another rule took over
            if outcome is Outcome.GOAL_ACHIEVED or then == LAND:
                self.activate(then)  # a return that could not arrive lands where it is
            elif outcome is not Outcome.INTERRUPTED:
                self.activate(KEEP_HOVERING)

        if math.dist(here, point) <= 0.3:
            self.activate(then)
            return
        self._activate(GO_TO_POINT, {"COORDINATES": [round(v, 2) for v in point]}, timeout, arrived)

    def activate(self, behavior: str, arguments: dict | None = None) -> None:
        self._activate(behavior, arguments or {})

    def _activate(self, behavior: str, arguments: dict, timeout: float | None = None,
                  on_end: Callable | None = None) -> None:
        coordinator, named = self._of.coordinator, self._of.named
        result = coordinator.activate(named.get(behavior, behavior), arguments, priority="higher", source="safety",
                                      timeout=timeout, on_end=on_end, check_preconditions=False)
        if not result.accepted and behavior == GO_TO_POINT and result.outcome is Outcome.GOAL_ACHIEVED \
                and on_end is not None:
            on_end(Outcome.GOAL_ACHIEVED, result.message, None)  # already there: what comes after
            return
        if not result.accepted and behavior != LAND:
            logger.warning("safety rule %s: %s refused (%s); landing", self.rule.name, named.get(behavior, behavior),
                           result.message)
            coordinator.activate(named[LAND], {}, priority="higher", source="safety", check_preconditions=False)


def _kind(rule: SafetyRule) -> ContingencyKind:
    """The table's entry for ``rule``'s contingency; ``land`` when no installed package gives it any more."""
    kinds = contingency_kinds()
    if rule.contingency.kind not in kinds:
        logger.error("safety rule %s: no installed package gives the contingency %s; landing", rule.name,
                     rule.contingency.kind)
        return kinds[LAND_CONTINGENCY.kind]
    return kinds[rule.contingency.kind]


__all__ = ["Actions", "Contingencies"]
