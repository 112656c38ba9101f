"""What evaluating rules may spend: a memory's bound on the work of one ask (or of one engine step), and the
refusal of an evaluation that would pass it.

Apart from the evaluation (``joins.py``) so that a memory holds its bound without importing the rules' modules: a
memory with no rules (an engine whose catalog has none) never imports them.
"""

from __future__ import annotations

from dataclasses import dataclass

from aeroexec.beliefs.errors import EvaluationRefused

TYPE_CHECKING = False  # typing is not imported at run time
if TYPE_CHECKING:
    from aeroexec.beliefs.expression import Rule

#: Most partial answers one evaluation of a rule's body may build
MAX_ROWS = 5_000_000


@dataclass
class Budget:
    """What evaluating rules may spend in one ask: ``work`` units (a partial answer built or a derived belief
    stored is one; see ``joins.py``'s :data:`EACH_COST`, :data:`CALL_COST`), None for no bound. An evaluation that
    would pass it is refused (:class:`EvaluationRefused`) before it builds what it cannot afford."""

    work: int | None = None
    spent: int = 0
    why: str = ""  # what the bound is for, said in a refusal
    #: renewed at every ask; False: renewed by its owner (an engine, at each step: the bound is per step)
    per_ask: bool = True

    def left(self) -> int:
        return MAX_ROWS if self.work is None else max(0, self.work - self.spent)  # MAX_ROWS: more than ever fits

    def charge(self, units: int, rule: Rule) -> None:
        self.spent += units
        if self.work is not None and self.spent > self.work:
            raise refused(rule, self)


def refused(rule: Rule, budget: Budget) -> EvaluationRefused:
    return EvaluationRefused(f"evaluating the rule {rule} takes more than {budget.work:,} units of work in one "
                             f"{'ask' if budget.per_ask else 'engine step'}{budget.why}: refused", rule.file,
                             rule.line)


__all__ = ["MAX_ROWS", "Budget", "refused"]
