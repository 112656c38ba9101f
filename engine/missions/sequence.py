"""WRONG_SEQUENCE in Python missions: the phenomena's state machines simulated along the entry function's AST.

Requests are taken as done, as the specialist does (paper section 4.3). The policy never reports an error that
a run reaching the call could avoid: each phenomenon is either known (the same state on every path that
reaches the call) or unknown, and a call is checked only against the phenomena that are known.

- ``if``/``match``: each branch is checked from the state before it (a constant test picks its branch); after
  it a phenomenon stays known only if every branch that falls through agrees on it.
- loops: the body is checked once, from the state every iteration starts in (found by iterating silently to a
  fixed point): a phenomenon one pass through the body may change is unknown there; after the loop, the states
  where it can end (test false, ``break``) must agree too.
- ``try``: handlers start unknown when the ``try`` body runs behaviors, ``finally`` when any part does;
  ``return``, ``raise``, ``break`` and ``continue`` end their path, and code no path reaches is not checked.
- a call of a local function that runs behaviors, a behavior named by a variable, inhibiting a behavior with
  transitions, or a behavior call inside ``x if c else y``, ``and``/``or``, a comprehension or a lambda
  makes the phenomena it may change unknown.
Not modelled (the program is taken at its word): reactive behaviors such as LAND on a low battery, and context
managers that swallow exceptions.
"""

from __future__ import annotations

import ast

from aeroexec.engine.catalog import BehaviorCatalog, BehaviorSpecialist
from aeroexec.engine.catalog.specialist import PhenomenonState, Request
from aeroexec.engine.errors import WRONG_SEQUENCE

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, Protocol
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

State = dict[str, PhenomenonState | None]  # None: unknown
#: How deep the walk follows calls of the program's own functions into their bodies.
MAX_INLINED = 8


class MissionChecker(Protocol):
    """What the walker uses of the mission's checker (:class:`~aeroexec.engine.missions.check.MissionChecker`)."""

    specialist: BehaviorSpecialist
    catalog: BehaviorCatalog

    def report(self, node: ast.AST | None, message: str, kind: str = "", severity: str = "error") -> None: ...
    def behavior_requests(self, call: ast.Call, state: State | None = None,
                          ) -> list[tuple[str, str | None, dict[str, Any], set[str]]]: ...
    def calls_local_behaviors(self, call: ast.Call) -> bool: ...
    def local_function(self, call: ast.Call) -> ast.FunctionDef | ast.AsyncFunctionDef | None: ...
    def effectful(self, node: ast.AST) -> bool: ...


class SequenceWalker:
    """Walks a function body with the phenomena's states, reporting WRONG_SEQUENCE through the checker."""

    def __init__(self, checker: MissionChecker) -> None:
        self.checker, self.specialist = checker, checker.specialist
        self.unknown: State = dict.fromkeys(self.specialist.initial_states())
        self.loops: list[tuple[list[State | None], list[State | None]]] = []  # breaks, continues
        self.silent = 0  # > 0 while looking for a loop's fixed point: nothing is reported
        self.inlined: list[str] = []  # the program's functions being walked into, innermost last
        self.returns: list[list[State | None]] = []  # the states their return statements leave

    def check(self, function: ast.FunctionDef | ast.AsyncFunctionDef) -> None:
        """Walk a function's body from the mission's initial states (landed, lights off)."""
        self.check_body(function.body)

    def check_body(self, statements: list[ast.stmt]) -> None:
        """Walk statements (a function's body, or a script's) from the mission's initial states."""
        self.block(statements, self.specialist.initial_states())

    def join(self, *states: State | None) -> State | None:
        reached = [s for s in states if s is not None]
        if not reached:
            return None
        joined = dict(reached[0])
        for state in reached[1:]:
            for name, current in state.items():
                mine = joined[name]
                if mine is None or current is None or mine.state != current.state:
                    joined[name] = None
                elif mine.since != current.since:  # same state, reached after different behaviors
                    since = dict.fromkeys(b for s in (mine.since, current.since) if s for b in s.split(" or "))
                    joined[name] = PhenomenonState(mine.state, " or ".join(since) or None)
        return joined

    def block(self, statements: list[ast.stmt], state: State | None) -> State | None:
        for statement in statements:
            if state is None:
                break  # unreachable: not checked
            state = self.statement(statement, state)
        return state

    def statement(self, node: ast.stmt, state: State) -> State | None:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            return state
        ends = isinstance(node, ast.Return | ast.Raise | ast.Break | ast.Continue)
        if not self.checker.effectful(node) and not any(isinstance(n, ast.Break | ast.Continue)
                                                        for n in ast.walk(node)):
            return None if ends else state
        if isinstance(node, ast.If):
            state = self.expression(node.test, state)
            truth = _constant_truth(node.test)
            return self.join(None if truth is False else self.block(node.body, state),
                             None if truth is True else self.block(node.orelse, state))
        if isinstance(node, ast.For | ast.AsyncFor):
            return self.loop(node, self.expression(node.iter, state), None, can_finish=True)
        if isinstance(node, ast.While):
            return self.loop(node, state, node.test, can_finish=_constant_truth(node.test) is not True)
        if isinstance(node, ast.Try | ast.TryStar):
            return self.try_statement(node, state)
        if isinstance(node, ast.With | ast.AsyncWith):
            for item in node.items:
                state = self.expression(item.context_expr, state)
            return self.block(node.body, state)
        if isinstance(node, ast.Match):
            state = self.expression(node.subject, state)
            effectful_guard = any(c.guard and self.checker.effectful(c.guard) for c in node.cases)
            return self.join(state, *(self.block(c.body, self.unknown if effectful_guard else state)
                                      for c in node.cases))
        for child in ast.iter_child_nodes(node):
            state = self.expression(child, state)
        if self.loops and isinstance(node, ast.Break | ast.Continue):
            self.loops[-1][0 if isinstance(node, ast.Break) else 1].append(state)
        if self.returns and isinstance(node, ast.Return):
            self.returns[-1].append(state)
        return None if ends else state

    def loop(self, node: ast.For | ast.AsyncFor | ast.While, start: State | None, test: ast.expr | None,
             can_finish: bool) -> State | None:
        """Find silently the state every iteration starts in, then check the body (and ``test``) from it."""
        head = start
        for _ in range(len(self.unknown) + 2):
            self.silent += 1
            self.loops.append(([], []))
            end = self.block(node.body, self.expression(test, head) if test is not None else head)
            _, continues = self.loops.pop()
            self.silent -= 1
            following = self.join(start, end, *continues)
            if _states(following) == _states(head):
                break
            head = following
        else:
            head = self.join(start, self.unknown)
        entry = self.expression(test, head) if test is not None else head
        self.loops.append(([], []))
        self.block(node.body, entry)
        breaks, _ = self.loops.pop()
        return self.join(self.block(node.orelse, entry if can_finish else None), *breaks)

    def try_statement(self, node: ast.Try | ast.TryStar, state: State) -> State | None:
        effectful = self.checker.effectful
        raising = self.unknown if any(effectful(s) for s in node.body) else state
        normal = self.block(node.orelse, self.block(node.body, state))
        after = self.join(normal, *(self.block(h.body, raising) for h in node.handlers))
        if not node.finalbody:
            return after
        if any(effectful(s) for s in node.finalbody):  # a break or continue runs finally on its way out
            for breaks, continues in self.loops:
                breaks[:] = [self.unknown if s is not None else None for s in breaks]
                continues[:] = [self.unknown if s is not None else None for s in continues]
        tried = any(effectful(s) for s in (*node.body, *node.handlers, *node.orelse))
        final = self.block(node.finalbody, self.unknown if tried else self.join(after, state))
        return None if after is None else final

    def expression(self, node: ast.AST, state: State | None) -> State | None:
        if state is None or not self.checker.effectful(node):
            return state
        if isinstance(node, ast.IfExp):
            state = self.expression(node.test, state)
            return self.unknown if self.checker.effectful(node.body) or self.checker.effectful(node.orelse) else state
        if isinstance(node, ast.BoolOp):
            return self.unknown if any(self.checker.effectful(v) for v in node.values[1:]) else self.expression(
                node.values[0], state)
        if isinstance(node, ast.Lambda | ast.ListComp | ast.SetComp | ast.DictComp | ast.GeneratorExp):
            return self.unknown
        for child in ast.iter_child_nodes(node):
            state = self.expression(child, state)
        return self.call(node, state) if isinstance(node, ast.Call) else state

    def call(self, node: ast.Call, state: State | None) -> State | None:
        if state is None:
            return None
        checker = self.checker
        requests = checker.behavior_requests(node, state)
        if not requests:
            if not checker.calls_local_behaviors(node):
                return state
            return self.inline(node, state)
        for request in requests:
            state = self.request(node, request, state)
        return state

    def inline(self, node: ast.Call, state: State) -> State | None:
        """Walk into a function of the program's own that the call runs (``drone_start(uav)``), from ``state``;
        the states its returns leave joined. Methods, recursion and functions defined twice are unknown."""
        function = self.checker.local_function(node)
        if function is None or function.name in self.inlined or len(self.inlined) >= MAX_INLINED:
            return self.unknown
        self.inlined.append(function.name)
        self.returns.append([])
        saved, self.loops = self.loops, []
        try:
            end = self.block(function.body, state)
        finally:
            self.loops = saved
            returned = self.returns.pop()
            self.inlined.pop()
        return self.join(end, *returned)

    def request(self, node: ast.Call, request: tuple[str, str | None, dict[str, Any], set[str]],
                state: State | None) -> State | None:
        if state is None:
            return None
        checker = self.checker
        function, name, arguments, uncertain = request
        if name is None:
            return self.unknown
        if checker.catalog.behavior(name) is None:
            return state
        transitions = [t for t in checker.catalog.transitions if name in t.behaviors]
        touched = {t.phenomenon for t in transitions}
        if function == "inhibit_behavior":
            return {p: None if p in touched else s for p, s in state.items()}
        known = {p: s for p, s in state.items() if s is not None}
        advanced, errors = self.specialist.advance(known, Request(name, arguments))
        for error in errors if not self.silent else ():
            checker.report(node, error.message, WRONG_SEQUENCE)
        result: State = {**state, **advanced}
        for phenomenon in touched:
            mine = [t for t in transitions if t.phenomenon == phenomenon]
            if any(t.argument and (t.argument in uncertain or "**" in uncertain) for t in mine):
                result[phenomenon] = None
            elif state[phenomenon] is None:
                finals = {t.final_state for t in mine if t.applies(name, arguments)}
                result[phenomenon] = PhenomenonState(finals.pop(), name) if len(finals) == 1 else None
        return result


def _states(state: State | None) -> dict[str, str | None] | None:
    return None if state is None else {p: s.state if s else None for p, s in state.items()}


def _constant_truth(node: ast.AST) -> bool | None:
    try:
        return bool(ast.literal_eval(node))
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return None
