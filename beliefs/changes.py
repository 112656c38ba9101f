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


__all__ = ["BeliefChange"]
