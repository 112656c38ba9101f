"""WRONG_SEQUENCE in behavior trees: the phenomena's state machines (flight, light) followed along every path.

Each node is analysed from the states it may be entered in and gives the states after it succeeds and after it
fails. A phenomenon is known (the same state on every path reaching the node) or unknown, and a behavior is
checked with the specialist's ``advance`` against the known phenomena only, so nothing is reported that a run
reaching the behavior could avoid. The policy, conservative everywhere:

- a behavior that fails may have stopped half-way: the phenomena it changes are unknown after its failure;
- sequences thread the success state; fallbacks try each alternative from the state the previous one failed
  in (from the same state when that alternative only consults beliefs); IfThenElse takes the condition's
  success state into its then branch and its failure state into its else branch;
- a Condition or QueryBelief (or a ``_skipIf``...) that consults a predicate named after a phenomenon
  (``flight_state`` for flight, ``light`` for light) makes that phenomenon unknown: the memory may disagree
  with the state machine;
- loops (Repeat, RetryUntilSuccessful, KeepRunningUntilFailure) and nodes that tick their children again
  (ReactiveSequence, ReactiveFallback, WhileDoElse) are checked from the state every pass starts in, found
  silently by iterating to a fixed point, and their first pass from the state the loop is entered in (a LAND
  before a Repeat of GO_TO_POINTs is wrong although a later pass could start hovering);
- children of a Parallel run together: each is checked with the phenomena the others change unknown;
- a node with a pre-condition may not run at all: its exits are joined with the state before it.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable

from aeroexec.engine.catalog.specialist import BehaviorSpecialist, PhenomenonState, Request
from aeroexec.engine.errors import WRONG_SEQUENCE
from aeroexec.trees.model import PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.ports import OPTIONS, parse_number, request_from_ports, template_keys
from aeroexec.trees.runtime.kinds import NodeKind, kind_of

State = dict[str, PhenomenonState | None]  # None: unknown
Exits = tuple[State | None, State | None]  # after SUCCESS, after FAILURE; None when it cannot end that way
Report = Callable[[TreeNode, str, str], None]


def join(*states: State | None) -> State | None:
    """What is known on every one of these paths (None: no path)."""
    reached = [s for s in states if s is not None]
    if not reached:
        return None
    result: State = {}
    for phenomenon in reached[0]:
        values = [s[phenomenon] for s in reached]
        first = values[0]
        if any(v is None or first is None or v.state != first.state for v in values):
            result[phenomenon] = None
            continue
        behaviors = dict.fromkeys(b for v in values if v.since for b in v.since.split(" or "))
        result[phenomenon] = PhenomenonState(first.state, " or ".join(behaviors) or None)
    return result


class SequenceChecker:
    """Walks a document's main tree with the phenomena's states, reporting WRONG_SEQUENCE through ``report``."""

    def __init__(self, document: TreeDocument, specialist: BehaviorSpecialist, report: Report) -> None:
        self.document, self.specialist, self.report = document, specialist, report
        self.catalog = specialist.catalog
        self.unknown: State = dict.fromkeys(self.specialist.initial_states())
        self.silent = 0
        self.stack: list[str] = []
        self._memo: dict[tuple, Exits] = {}
        self._reported: set[tuple[int, str]] = set()  # (node, message) said once

    def check(self) -> None:
        if self.document.main in self.document.trees:
            self.stack = [self.document.main]
            self.flow(self.document.root, dict(self.specialist.initial_states()), False)

    # -- helpers -------------------------------------------------------------------------------
    def forget(self, state: State | None, phenomena: set[str]) -> State | None:
        return None if state is None else {p: None if p in phenomena else s for p, s in state.items()}

    def related(self, expression: str) -> set[str]:
        """Phenomena a belief expression consults (its predicates are named after them)."""
        words = {w for w in _words(expression)}
        return {p for p in self.unknown if any(w == p or w.startswith(p + "_") for w in words)}

    def touched(self, node: TreeNode, seen: tuple[str, ...] = ()) -> set[str]:
        """Every phenomenon a behavior anywhere below ``node`` (subtrees included) may change."""
        found: set[str] = set()
        for n in node.walk():
            kind = kind_of(n.type)
            if kind is not None and kind.subtree:
                tree = n.ports.get("ID", "").strip()
                if tree in self.document.trees and tree not in seen:
                    found |= self.touched(self.document.trees[tree], (*seen, tree))
            name = _behavior_name(n, kind)
            found |= {t.phenomenon for t in self.catalog.transitions if name in t.behaviors}
            if kind is None and n.type not in self.catalog:
                found |= set(self.unknown)
        return found

    def quietly(self, function: Callable[[], Exits]) -> Exits:
        self.silent += 1
        try:
            return function()
        finally:
            self.silent -= 1

    def loop(self, start: State, body: Callable[[State], tuple[Exits, State | None]]) -> Exits:
        """Exits of a node whose body runs again from the states ``body`` hands back, checked from its fixed point.
        The first pass, from ``start``, reports what it finds wrong (it runs from there whatever the later passes
        do); the passes towards the fixed point are silent; the one from the fixed point reports again."""
        head, first = start, None
        for _ in range(len(self.unknown) + 2):
            if first is None:
                first, back = body(head)
            else:
                _, back = self.quietly(lambda h=head: body(h))  # type: ignore[misc,return-value]
            following = join(start, back)
            if _names(following) == _names(head):
                break
            head = following  # type: ignore[assignment]
        else:
            head = dict(self.unknown)
        if head is start and first is not None:  # the first pass was the fixed point's
            return first
        exits, _ = body(head)
        return exits

    # -- the walk ------------------------------------------------------------------------------
    def flow(self, node: TreeNode, state: State, looping: bool) -> Exits:
        conditions = [node.ports[a] for a in PRECONDITIONS if node.ports.get(a, "").strip()]
        if not conditions:
            return self.node(node, state, looping)
        entry = self.forget(state, set().union(*(self.related(c) for c in conditions)))
        success, failure = self.node(node, entry, looping)
        return join(success, entry), join(failure, entry)

    def node(self, node: TreeNode, state: State, looping: bool) -> Exits:
        kind = kind_of(node.type)
        if kind is None:  # a catalog behavior, or a node nothing knows
            if node.type in self.catalog and not node.children:
                return self.behavior(node, node.type, state)
            return self.opaque(node, state, looping)
        looping = looping or kind.loops
        flow = self.flows.get(kind.flow, SequenceChecker.opaque)
        exits = flow(self, node, state, looping, kind)
        return exits if exits is not None else self.opaque(node, state, looping)

    def opaque(self, node: TreeNode, state: State, looping: bool, kind: NodeKind | None = None) -> Exits:
        """A node the check cannot follow: what the behaviors below it change is unknown after it."""
        opaque = self.forget(state, self.touched(node))
        for child in node.children:  # still look inside it
            self.flow(child, dict(self.unknown), looping)
        return opaque, opaque

    # -- the flows the node kinds name (``trees.runtime.kinds``); None: the node is followed as opaque ----------
    def _sequence(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.series(node.children, state, False, looping)[0]

    def _sequence_with_memory(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.series(node.children, state, False, looping, looping)[0]

    def _reactive_sequence(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.loop(state, lambda s: self.series(node.children, s, False, True))

    def _fallback(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.series(node.children, state, True, looping)[0]

    def _reactive_fallback(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.loop(state, lambda s: self.series(node.children, s, True, True))

    def _parallel(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.parallel(node.children, state, looping)

    def _if_then_else(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        return self.branches(node.children, state, looping)[0] if len(node.children) in (2, 3) else None

    def _while_do_else(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        children = node.children
        return self.loop(state, lambda s: self.branches(children, s, True)) if len(children) in (2, 3) else None

    def _subtree(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return self.subtree(node, state, looping)

    def _consult(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        after = self.forget(state, self.related(node.ports.get("belief", "")))
        return after, after

    def _pass(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return state, state

    def _succeed(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return state, None

    def _fail(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits:
        return None, state

    def _ask(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        behavior = _behavior_name(node, kind)
        return self.behavior(node, behavior, state) if behavior in self.catalog and not node.children else None

    def _decorated(self, node: TreeNode, state: State, looping: bool) -> Exits | None:
        return self.flow(node.children[0], state, looping) if len(node.children) == 1 else None

    def _decorator(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        return self._decorated(node, state, looping)

    def _invert(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        exits = self._decorated(node, state, looping)
        return None if exits is None else (exits[1], exits[0])

    def _force_success(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        exits = self._decorated(node, state, looping)
        return None if exits is None else (join(*exits), None)

    def _force_failure(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        exits = self._decorated(node, state, looping)
        return None if exits is None else (None, join(*exits))

    def _run_once(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        exits = self._decorated(node, state, looping)
        if exits is None or not looping:
            return exits
        return join(exits[0], state), exits[1]

    def _repeat(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        if len(node.children) != 1:
            return None
        if parse_number(node.ports.get("num_cycles", "")) == 0:
            return state, None
        return self._again_after_success(node, state)

    def _keep_running_until_failure(self, node: TreeNode, state: State, looping: bool, kind: NodeKind
                                    ) -> Exits | None:
        if len(node.children) != 1:
            return None
        return None, self._again_after_success(node, state)[1]

    def _again_after_success(self, node: TreeNode, state: State) -> Exits:
        child = node.children[0]
        return self.loop(state, lambda s: (lambda e: (e, e[0]))(self.flow(child, s, True)))

    def _retry(self, node: TreeNode, state: State, looping: bool, kind: NodeKind) -> Exits | None:
        if len(node.children) != 1:
            return None
        child = node.children[0]
        return self.loop(state, lambda s: (lambda e: (e, e[1]))(self.flow(child, s, True)))

    flows: dict[str, Callable[..., Exits | None]] = {
        "sequence": _sequence, "sequence_with_memory": _sequence_with_memory,
        "reactive_sequence": _reactive_sequence, "fallback": _fallback, "reactive_fallback": _reactive_fallback,
        "parallel": _parallel, "if_then_else": _if_then_else, "while_do_else": _while_do_else,
        "subtree": _subtree, "consult": _consult, "pass": _pass, "succeed": _succeed, "fail": _fail, "ask": _ask,
        "decorator": _decorator, "invert": _invert, "force_success": _force_success,
        "force_failure": _force_failure, "run_once": _run_once, "repeat": _repeat, "retry": _retry,
        "keep_running_until_failure": _keep_running_until_failure, "opaque": opaque,
    }
    """What each ``flow`` word of a node kind means to the check."""

    def series(self, children: list[TreeNode], state: State, fallback: bool, looping: bool,
               resume: bool = False) -> tuple[Exits, State | None]:
        """Children in order (``fallback``: until one succeeds); ``resume``: a failed child may be entered again.

        Returns the exits and every state a child may end in (for nodes that tick their children again).
        """
        current: State | None = state
        others: list[State | None] = []
        every: list[State | None] = []
        for child in children:
            if current is None:
                break
            entry = self.forget(current, self.touched(child)) if resume else current
            success, failure = self.flow(child, entry, looping)
            every += [success, failure]
            others.append(success if fallback else failure)
            current = failure if fallback else success
        exits = (join(*others), current) if fallback else (current, join(*others))
        return exits, join(*every)

    def branches(self, children: list[TreeNode], state: State, looping: bool) -> tuple[Exits, State | None]:
        test_success, test_failure = self.flow(children[0], state, looping)
        then = self.flow(children[1], test_success, looping) if test_success is not None else (None, None)
        other = self.flow(children[2], test_failure, looping) if len(children) == 3 and test_failure is not None \
            else (None, test_failure)
        exits = join(then[0], other[0]), join(then[1], other[1])
        return exits, join(*then, *other)

    def parallel(self, children: list[TreeNode], state: State, looping: bool) -> Exits:
        touched = [self.touched(child) for child in children]
        counts = Counter(phenomenon for found in touched for phenomenon in found)  # linear in the children
        ends: list[State | None] = []
        for index, child in enumerate(children):
            others = {p for p, count in counts.items() if count > (p in touched[index])}
            ends.append(join(*self.flow(child, self.forget(state, others), looping)))
        merged: State = {}
        for phenomenon, before in state.items():
            changed = [e[phenomenon] for e in ends if e is not None and e[phenomenon] != before]
            merged[phenomenon] = before if not changed else join(*({phenomenon: c} for c in changed))[phenomenon]  # type: ignore[index]
        return merged, merged

    def subtree(self, node: TreeNode, state: State, looping: bool) -> Exits:
        tree = node.ports.get("ID", "").strip()
        if tree not in self.document.trees or tree in self.stack:
            unknown = dict(self.unknown)
            return unknown, unknown
        key = (tree, looping, bool(self.silent),
               tuple(sorted((p, (s.state, s.since) if s else None) for p, s in state.items())))
        if key not in self._memo:  # a tree used many times from the same states is walked once
            self.stack.append(tree)
            try:
                self._memo[key] = self.flow(self.document.trees[tree], state, looping)
            finally:
                self.stack.pop()
        success, failure = self._memo[key]
        return (dict(success) if success is not None else None), (dict(failure) if failure is not None else None)

    def behavior(self, node: TreeNode, behavior: str, state: State) -> Exits:
        descriptor = self.catalog.behavior(behavior)
        kind = kind_of(node.type)
        # the kind's own ports are no arguments (the options, ``timeout``, go to the behavior)
        skip = tuple(p for p in kind.ports if p not in OPTIONS) if kind is not None else ()
        arguments, _ = request_from_ports(descriptor, node.ports, None, skip)
        uncertain = {name for name, value in arguments.items() if isinstance(value, str) and template_keys(value)}
        transitions = [t for t in self.catalog.transitions if behavior in t.behaviors]
        touched = {t.phenomenon for t in transitions}
        known = {p: s for p, s in state.items() if s is not None}
        advanced, errors = self.specialist.advance(known, Request(behavior, arguments))
        if not self.silent:
            for error in errors:
                if (id(node), error.message) not in self._reported:  # a loop's first pass and the others
                    self._reported.add((id(node), error.message))
                    self.report(node, error.message, WRONG_SEQUENCE)
        success: State = {**state, **advanced}
        for phenomenon in touched:
            mine = [t for t in transitions if t.phenomenon == phenomenon]
            if any(t.argument and t.argument in uncertain for t in mine):
                success[phenomenon] = None
            elif state[phenomenon] is None:
                finals = {t.final_state for t in mine if t.applies(behavior, arguments)}
                success[phenomenon] = PhenomenonState(finals.pop(), behavior) if len(finals) == 1 else None
        return success, self.forget(state, touched)


def _behavior_name(node: TreeNode, kind: NodeKind | None) -> str:
    """The catalog behavior a node runs: its own name, or the one its kind's ``behavior_port`` names."""
    if kind is not None and kind.behavior_port:
        return node.ports.get(kind.behavior_port, "").strip()
    return node.type


def _words(text: str) -> list[str]:
    word, words = "", []
    for char in text + " ":
        if char.isalnum() or char == "_":
            word += char
        elif word:
            words.append(word)
            word = ""
    return words


def _names(state: State | None) -> dict[str, str | None] | None:
    return None if state is None else {p: s.state if s else None for p, s in state.items()}
