"""Belief updaters (paper section 5.2): processes that keep a category of beliefs current.

An updater runs at its own period on the engine's clock and publishes what it
observes. Publishing a *scope* (a pattern such as ``visible(?)``) replaces every
belief in that scope: beliefs no longer observed are retracted (the paper's null
persistence), new ones are added, unchanged ones are left alone so listeners only
hear of real changes.
"""

from __future__ import annotations

import abc
import logging
from collections.abc import Callable, Iterable

from aeroexec.beliefs.expression import Goal
from aeroexec.beliefs.memory import BeliefMemory
from aeroexec.beliefs.parser import parse_belief, parse_expression
from aeroexec.beliefs.terms import Struct, match

log = logging.getLogger(__name__)


class BeliefUpdater(abc.ABC):
    """Observes something and updates the memory at most every ``period`` seconds."""

    def __init__(self, name: str, period: float = 0.2) -> None:
        if period < 0:
            raise ValueError(f"the period of belief updater {name} cannot be negative")
        self.name = name
        self.period = period
        self._last: float | None = None

    def due(self, now: float) -> bool:
        return self._last is None or now - self._last >= self.period - 1e-9

    def tick(self, memory: BeliefMemory, now: float) -> None:
        """Called on every engine tick; runs :meth:`update` when the period has passed.

        An updater that raises is logged and skipped for this period; the engine goes on.
        """
        last = self._last  # (every engine period of every updater: due(), without its call)
        if last is not None and now - last < self.period - 1e-9:
            return
        self._last = now
        try:
            self.update(memory, now)
        except Exception:
            log.exception("belief updater %s failed", self.name)

    def refresh(self, memory: BeliefMemory, now: float) -> None:
        """Update at once, whatever the period (e.g. before a decision that must see the latest state)."""
        self._last = None
        self.tick(memory, now)

    @abc.abstractmethod
    def update(self, memory: BeliefMemory, now: float) -> None:
        """Observe and write beliefs; use :func:`publish` for sets of beliefs."""


class FunctionUpdater(BeliefUpdater):
    """An updater made of a function ``(memory, now) -> None``."""

    def __init__(self, name: str, function: Callable[[BeliefMemory, float], None], period: float = 0.2) -> None:
        super().__init__(name, period)
        self._function = function

    def update(self, memory: BeliefMemory, now: float) -> None:
        self._function(memory, now)


def publish(memory: BeliefMemory, scope: str | Struct, beliefs: Iterable[str | Struct]) -> tuple[int, int]:
    """Make the beliefs matching ``scope`` exactly ``beliefs``; returns (added, removed).

    ``publish(memory, "visible(?)", ["visible(marker_3)"])`` retracts every other
    ``visible`` belief. Each belief must match the scope.
    """
    if isinstance(scope, str):
        expression = parse_expression(scope)
        if len(expression.literals) != 1 or type(expression.literals[0]) is not Goal:
            raise ValueError(f"the scope {scope} must be a single predicate pattern")
        scope = expression.literals[0].term
    wanted = [b if type(b) is Struct else parse_belief(b) for b in beliefs]
    for belief in wanted:
        if not match(scope, belief, {}):
            raise ValueError(f"{belief} is outside the scope {scope} it is published in")
    present = set(memory.matching(scope))
    keep = set(wanted)
    removed = 0
    for belief in present - keep:
        removed += memory.remove(belief)
    added = sum(1 for belief in wanted if memory.add(belief))
    return added, removed
