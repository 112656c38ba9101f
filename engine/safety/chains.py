"""Safety rules' plans solved as chains: the stored goals asked of the memory (one look-up when a single goal asks
the value of a key, ``position(self, ?p)``, or spreads it into variables, ``position(self, (?x, ?y, ?z))``), then
each computed goal (a registered function, its inputs bound by the goals before it, one fresh output) called on
every solution as the memory's solver calls it, without planning and unifying each time: what most monitors ask,
at a fraction of the cost. A plan that forms no chain is asked of the memory whole.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from aeroexec.beliefs import Conjunction, Goal, Var
from aeroexec.beliefs.terms import Struct, from_python, to_python

logger = logging.getLogger(__name__)
_WHOLE = "?_safety_value"


def compile_chain(goals: Conjunction, memory: Any) -> Callable[[Any], list[dict]] | None:
    """A function solving ``goals`` on a memory as a chain; None when they form none, or nothing is gained."""
    stored: list[Goal] = []
    steps: list[tuple[Callable, tuple, str]] = []
    bound: set[Var] = set()
    for literal in goals.literals:
        if type(literal) is not Goal:
            return None
        term = literal.term
        found = memory.function(*term.signature)
        if found is None:
            if memory.is_computed(*term.signature) or steps:  # a built-in; or stored after a computed goal
                return None
            stored.append(literal)
            bound |= set(variables(term))
            continue
        function, inputs = found
        output = term.args[-1] if inputs == len(term.args) - 1 else None
        if type(output) is not Var or output in bound or output.anonymous or \
                any(type(a) is Var and a not in bound or type(a) is not Var and variables(a) for a in term.args[:-1]):
            return None  # an input not bound, or a compound with variables in it: the memory's solver substitutes
        steps.append((function, tuple(_argument(a) for a in term.args[:-1]), output.name))
        bound.add(output)
    keyed = _keyed(stored)
    if keyed is None and not steps:
        return None
    conjunction = Conjunction(tuple(stored), ", ".join(str(g) for g in stored)) if stored else None
    return _chain(conjunction, keyed, tuple(steps))


def _keyed(stored: list[Goal]) -> tuple[Conjunction, str, tuple[str, ...] | None] | None:
    """A single stored goal asking the value of a ground key: the goal asking it into one variable, its predicate,
    and the variables a flat tuple of distinct ones spreads it into (None: the value is the variable)."""
    if len(stored) != 1:
        return None
    term = stored[0].term
    if len(term.args) < 2 or any(variables(a) for a in term.args[:-1]):
        return None
    value = term.args[-1]
    if type(value) is Var:
        return None if value.anonymous else (Conjunction(tuple(stored), str(stored[0])), term.name, None)
    if type(value) is not tuple or not value or any(type(v) is not Var or v.anonymous for v in value) or \
            len(set(value)) != len(value):
        return None
    goal = Goal(Struct(term.name, (*term.args[:-1], Var(_WHOLE))))
    return Conjunction((goal,), str(goal)), term.name, tuple(v.name for v in value)


def _chain(stored: Conjunction | None, keyed: tuple | None, steps: tuple) -> Callable[[Any], list[dict]]:
    def solve(memory: Any) -> list[dict]:
        if stored is None:
            solutions = [{}]
        elif keyed is not None and memory.exclusive(keyed[1]):
            first = memory.query(keyed[0])
            solutions = [] if first is None else [first]
            names = keyed[2]
            if first is not None and names is not None:  # spread the value into its variables, as unifying does
                value = first.pop(_WHOLE)
                if not isinstance(value, tuple | list) or len(value) != len(names):
                    solutions = []
                else:
                    first.update(zip(names, value, strict=True))
        else:
            solutions = memory.query_all(stored)
        found = []
        for solution in solutions:
            for function, args, name in steps:
                values = [_input(solution[a]) if variable else a for variable, a in args]
                try:
                    value = function(*values)
                except Exception:  # as the memory's solver: a broken computed predicate fails its goal
                    logger.exception("computed predicate %s failed", name)
                    value = None
                if value is None or value is False:
                    break
                solution[name] = value if type(value) is float or _plain(value) else to_python(from_python(value))
            else:
                found.append(solution)
        return found
    return solve


def _argument(arg: Any) -> tuple[bool, Any]:
    """An input of a computed goal, prepared once: (True, a variable's name) or (False, the constant as the solver
    hands it)."""
    return (True, arg.name) if type(arg) is Var else (False, _input(arg))


def _input(value: Any) -> Any:
    """An input of a computed goal as the solver hands it: a term (a list is a ListTerm)."""
    return value if _plain(value) else from_python(value)


def _plain(value: Any) -> bool:
    """A number, an atom, or a tuple of them: the same as a term and as a Python value."""
    kind = type(value)
    if kind is float or kind is int or kind is str:
        return True
    if kind is not tuple:
        return False
    for item in value:
        kind = type(item)
        if kind is not float and kind is not int and kind is not str:
            return False
    return True


def variables(term: Any) -> list[Var]:
    """The variables of a term, in order."""
    if type(term) is Var:
        return [term]
    if isinstance(term, tuple):
        return [v for item in term for v in variables(item)]
    if isinstance(term, Struct):
        return [v for item in term.args for v in variables(item)]
    return []


__all__ = ["compile_chain", "variables"]
