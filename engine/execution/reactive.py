"""The bookkeeping of the reactive rules (Algorithm 5): which beliefs their conditions read, which of those
changed since the rules were last evaluated, and whether each rule held then.

A rule's condition is evaluated again only when a belief it reads has changed (always, when it reads a computed
predicate: those change without any belief doing so). The coordinator runs the rules at all only after a behavior
event or a change of a belief some rule reads (any belief, when one reads a computed predicate), so beliefs no rule
reads (the position, the speed...) change without costing the rules anything: once the rules have first run (when
what they read is known), the memory tells the watch only of the predicates they read.
"""

from __future__ import annotations

from collections.abc import Callable

from aeroexec.beliefs import BeliefMemory
from aeroexec.engine.catalog.descriptors import ReactiveRule

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

Signature = tuple[str, int]


class RuleWatch:
    """Listens to the memory for the reactive ``rules`` and remembers whether each held when last evaluated."""

    def __init__(self, rules: tuple[ReactiveRule, ...], memory: BeliefMemory) -> None:
        self.rules = rules
        self.memory = memory
        self.held: dict[int, bool] = {}  # rule index -> whether its condition held when last evaluated
        #: whether a belief a rule reads has changed since the rules were last run (read every engine period: an
        #: attribute, not a call); True until they first run
        self.due = True
        self._changed: set[Signature] = set()  # predicates changed since the rules were last run
        self._inputs: dict[int, tuple[frozenset, bool]] = {}  # rule -> its predicates, and if any is computed
        self._read: frozenset[Signature] | None = None  # what the rules read (None: any belief, or not known yet)
        self._read_known = False
        self._unsubscribe = memory.subscribe(self._belief_changed)  # every belief, until what the rules read is known

    def take_changes(self) -> set[Signature]:
        """The predicates changed since the rules were last run (the rules run now)."""
        if not self._read_known:  # at the first run: the vocabulary and the computed predicates are set by now
            self._read, self._read_known = self._rules_read(), True
            if self._read is not None:  # from now on, only the predicates the rules read (none: nothing)
                self._unsubscribe()
                if self._read:
                    self._unsubscribe = self.memory.subscribe(self._belief_changed, {name for name, _ in self._read})
        self.due = False
        changed, self._changed = self._changed, set()
        return changed

    def evaluate(self, index: int, rule: ReactiveRule, event: bool, changed: set[Signature],
                 holds: Callable[[ReactiveRule], bool]) -> tuple[bool, bool]:
        """Whether rule ``index`` holds now, and whether it has just come to hold (``holds`` checks its condition
        when it must be checked: after an event, the first time, or when a belief it reads changed)."""
        held = self.held
        checked = event or index not in held or self._touched(index, rule, changed)
        now = holds(rule) if checked else held[index]  # else none of the beliefs it reads changed: as it did
        rising = now and not held.get(index, False)
        held[index] = now
        return now, rising

    def _touched(self, index: int, rule: ReactiveRule, changed: set[Signature]) -> bool:
        """Whether a belief the rule's condition reads has changed (always, for computed predicates)."""
        if rule.condition is None:
            return False
        inputs = self._inputs.get(index)
        if inputs is None:  # the stored predicates it reads, through the rules of derived ones
            inputs = self._inputs[index] = self.memory.reads(rule.condition.predicates)
        return inputs[1] or not inputs[0].isdisjoint(changed)

    def _rules_read(self) -> frozenset[Signature] | None:
        """The predicates the rules' conditions read; None when one reads a computed predicate."""
        read: set[Signature] = set()
        for rule in self.rules:
            predicates, computed = self.memory.reads(rule.condition.predicates if rule.condition is not None
                                                     else frozenset())
            if computed:
                return None
            read |= predicates
        return frozenset(read)

    def _belief_changed(self, change: Any) -> None:
        belief = change.belief
        signature = (belief.name, len(belief.args))  # Struct.signature, without the property's call
        self._changed.add(signature)
        if self._read is None or signature in self._read:  # else no rule reads it: nothing to run them for
            self.due = True
