"""A change of the belief memory, as its listeners are told of it."""

from __future__ import annotations

from dataclasses import dataclass

from aeroexec.beliefs.terms import Struct, format_term


@dataclass(frozen=True, slots=True)
class BeliefChange:
    """One change of the memory: ``kind`` is "added" or "removed".

    ``reason`` says why: "add", "remove", "replaced" (retracted by an exclusive
    value), "expired" (its persistence ran out), "clear", or "shared" (a belief the memory answers from rows it
    shares with others came or went: it stores nothing, :meth:`BeliefMemory.announce
    <aeroexec.beliefs.memory.BeliefMemory.announce>`).
    """

    kind: str
    belief: Struct
    reason: str
    time: float

    def __str__(self) -> str:
        sign = "+" if self.kind == "added" else "-"
        return f"{sign}{format_term(self.belief)} ({self.reason})"


_NEW = BeliefChange.__new__
_KIND, _BELIEF, _REASON, _TIME = (BeliefChange.kind.__set__, BeliefChange.belief.__set__,  # type: ignore[attr-defined]
                                  BeliefChange.reason.__set__, BeliefChange.time.__set__)  # type: ignore[attr-defined]


def belief_change(kind: str, belief: Struct, reason: str, time: float) -> BeliefChange:
    """``BeliefChange(kind, belief, reason, time)``, made by filling its slots: the frozen dataclass's ``__init__``
    sets each field through ``object.__setattr__`` (~0.8 µs; this ~0.4 µs), and the memory makes one for every
    change it tells its listeners of (a flying drone's position, speed and orientation: every other period)."""
    change = _NEW(BeliefChange)
    _KIND(change, kind)
    _BELIEF(change, belief)
    _REASON(change, reason)
    _TIME(change, time)
    return change


__all__ = ["BeliefChange", "belief_change"]
