"""Beliefs held once for several memories: the rows of one predicate that every memory sharing them answers from,
without storing them (a fleet's table of where its drones are, one per process however many drones it flies).

A :class:`SharedBeliefs` is an indexed :class:`~aeroexec.beliefs.relation.Relation` written by its owner. A memory
that shares it (:meth:`BeliefMemory.share <aeroexec.beliefs.memory.BeliefMemory.share>`, through a
:class:`SharedView` that may hide some keys: a drone does not hear itself) answers a goal of that predicate from its
own stored beliefs first, then from the shared rows whose key it does not hold itself: what a memory knows itself
is never replaced by what it shares. A question with the key given is one look-up in each; the shared rows are
never copied, so a change costs one write whatever the number of memories. Questions and rules read them (a
rule reading shared beliefs is evaluated again whenever asked, as one reading a computed predicate); the memory's
listeners, its event log and ``beliefs()`` see only what the memory stores (its owner may
:meth:`~aeroexec.beliefs.memory.BeliefMemory.announce` a row that came or went).
"""

from __future__ import annotations

from collections.abc import Iterator

from aeroexec.beliefs.relation import Relation
from aeroexec.beliefs.steps import FactStep
from aeroexec.beliefs.terms import Struct, match, variables

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

class SharedBeliefs:
    """The beliefs ``name(...)`` of arity ``arity`` several memories answer from; exclusive by default (one value per
    key: all arguments but the last)."""

    def __init__(self, name: str, arity: int, exclusive: bool = True) -> None:
        self.relation = Relation(name, arity, exclusive)

    @property
    def signature(self) -> tuple[str, int]:
        return self.relation.name, self.relation.arity

    @property
    def version(self) -> int:
        return self.relation.version

    def put(self, args: tuple) -> None:
        """Hold ``name(*args)`` (replacing the row of its key, when exclusive)."""
        if args not in self.relation.rows:
            self.relation.insert(args)

    def drop(self, key: tuple) -> None:
        """Forget the row of ``key`` (exclusive beliefs) or the row ``key`` itself."""
        rel = self.relation
        row = rel.by_key.get(key) if rel.by_key is not None else (key if key in rel.rows else None)
        if row is not None:
            rel.delete(row)

    def get(self, key: tuple) -> tuple | None:
        """The row of ``key`` (exclusive beliefs), None when none."""
        by_key = self.relation.by_key
        return by_key.get(key) if by_key is not None else None

    def __len__(self) -> int:
        return len(self.relation.rows)

    def view(self, hidden: tuple[tuple, ...] = ()) -> SharedView:
        """What one memory answers from: every row but those of the keys in ``hidden``."""
        return SharedView(self, frozenset(hidden))


class SharedView:
    """:class:`SharedBeliefs` as one memory sees them (``hidden``: keys it is not answered)."""

    __slots__ = ("beliefs", "hidden")

    def __init__(self, beliefs: SharedBeliefs, hidden: frozenset[tuple]) -> None:
        self.beliefs, self.hidden = beliefs, hidden

    @property
    def signature(self) -> tuple[str, int]:
        return self.beliefs.signature


class SharedStep:
    """A goal on a shared predicate: the memory's stored rows, then the shared rows whose key it does not hold.

    Ready (for the planner) once its key is bound: then it is two look-ups; unbound, it runs last and lists all.
    """

    __slots__ = ("goal", "needs", "shared", "stored", "vars")

    def __init__(self, goal: Struct, exclusive: bool, shared: SharedView) -> None:
        self.goal = goal
        self.stored = FactStep(goal, exclusive)
        self.shared = shared
        self.vars = self.stored.vars
        self.needs = frozenset(v for a in goal.args[:-1] for v in variables(a))

    @property
    def signature(self) -> tuple[str, int]:
        return self.stored.signature

    def ready(self, bound: set) -> bool:
        return self.needs <= bound

    def solve(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        yield from self.stored.solve(relations, bindings, ranges)
        rel = self.shared.beliefs.relation
        if not rel.rows:
            return
        own = relations.get(self.stored.signature)
        held: Any = own.by_key if own is not None and own.by_key is not None else ()
        hidden = self.shared.hidden
        pattern = self.goal.args
        for row in list(self.stored.candidates(rel, bindings, ranges)):
            key = row[:-1]
            if key in hidden or key in held:
                continue
            extended = dict(bindings)
            if all(match(pattern[p], row[p], extended) for p in range(len(row))):
                yield extended


__all__ = ["SharedBeliefs", "SharedStep", "SharedView"]
