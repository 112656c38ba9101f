"""BehaviorTree.CPP v4's control nodes as ``py_trees`` composites, with BehaviorTree.CPP's semantics.

| node | child FAILURE | child RUNNING |
|---|---|---|
| Sequence | restart from the first child | tick the same child again |
| ReactiveSequence | restart | restart: every child ticked again, the others halted |
| SequenceWithMemory | tick the failed child again | tick the same child again |

Fallback mirrors Sequence (memory while RUNNING, restart after SUCCESS or when every child failed);
ReactiveFallback ticks from the first child on every tick. Parallel ticks every child that has not completed
and succeeds once ``success_count`` children succeed (negative: all but ``-1 - n``), fails once
``failure_count`` fail or success became impossible; completing halts the running children. IfThenElse ticks its
condition only until it completes; WhileDoElse ticks it on every tick and halts the branch it leaves.

py_trees has no SKIPPED status: a skipped node ends SUCCESS with ``skipped`` set, and these composites treat it
as BehaviorTree.CPP does (passed over; all children skipped -> the composite is skipped too). Halting is
``stop(INVALID)``; a node halted while RUNNING stops the behavior it started.
"""

from __future__ import annotations

import abc
from collections.abc import Generator, Sequence
from typing import Any

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import Status

#: The fourth status of BehaviorTree.CPP; a node ends SUCCESS and ``skipped`` is set.
SKIPPED = "SKIPPED"
Result = Status | str
Ticking = Generator[Behaviour, None, Result]


def result_of(node: Behaviour) -> Result:
    """A node's status, SKIPPED when it was skipped."""
    return SKIPPED if node.status == Status.SUCCESS and getattr(node, "skipped", False) else node.status


def status_name(node: Behaviour) -> str:
    """The status as BehaviorTree.CPP names it: IDLE, RUNNING, SUCCESS, FAILURE or SKIPPED."""
    result = result_of(node)
    return "IDLE" if result == Status.INVALID else result if isinstance(result, str) else result.value


def tick_child(child: Behaviour) -> Ticking:
    """Tick one child (yielding every node ticked, as py_trees expects) and return its result."""
    yield from child.tick()
    return result_of(child)


def halt(node: Behaviour) -> None:
    """BehaviorTree.CPP's ``haltChild`` of a running node: it is stopped, and the behaviors it runs.

    A completed node keeps its status (shown until it starts again): ticking it again starts it afresh anyway.
    """
    if node.status == Status.RUNNING:
        node.stop(Status.INVALID)


def reset(node: Behaviour) -> None:
    """Back to IDLE (a running node is halted first)."""
    if node.status != Status.INVALID:
        node.stop(Status.INVALID)


def run_tick(node: Any, restart: Any) -> Any:
    """The tick of a node deciding its result in ``node.run()``: BehaviorTree.CPP's SKIPPED becomes SUCCESS +
    ``skipped``; ``restart()`` runs first when the node was not RUNNING."""
    if node.status != Status.RUNNING:
        restart()
        node.initialise()
    node.skipped = False
    result = yield from node.run()
    if result == SKIPPED:
        node.skipped, result = True, Status.SUCCESS
    if result != Status.RUNNING:
        node.stop(result)
    node.status = result
    yield node


class Control(py_trees.composites.Composite):
    """A composite whose ``run()`` generator decides its result from its children, BehaviorTree.CPP style."""

    def __init__(self, name: str, children: Sequence[Behaviour] | None = None) -> None:
        super().__init__(name, list(children or []))
        self.skipped = False

    @abc.abstractmethod
    def run(self) -> Ticking:
        """One tick of this control node, as a generator (every control node says how it ticks)."""

    def tick(self) -> Any:
        return run_tick(self, self.restart)

    def restart(self) -> None:
        """Starting again: the children it will tick are reset (shown IDLE until ticked)."""
        for child in self.children[self.restart_from():]:
            reset(child)

    def restart_from(self) -> int:
        """The first child reset when the node starts again (the rest keep their status for display)."""
        return 0

    def reset_children(self, start: int = 0) -> None:
        """Halt the running children from ``start`` on."""
        for child in self.children[start:]:
            halt(child)

    def tick_index(self, index: int) -> Ticking:
        self.current_child = self.children[index]
        return (yield from tick_child(self.children[index]))

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            self.halted()

    def halted(self) -> None:
        """Reset what a halt resets."""


class SequenceNode(Control):
    """BehaviorTree.CPP ``Sequence``: a RUNNING child is ticked again; a failure restarts from the first child.

    ``stop_on`` is the result that ends the node early (FAILURE; SUCCESS for a Fallback); ``restart_on_stop``
    False keeps the index there (SequenceWithMemory).
    """

    stop_on = Status.FAILURE
    restart_on_stop = True
    #: BehaviorTree.CPP's AsyncSequence/AsyncFallback (and SequenceWithMemory): a child that completed on its first
    #: tick hands control back to the tree (RUNNING) before the next child is ticked.
    asynchronous = False

    def __init__(self, name: str, children: Sequence[Behaviour] | None = None) -> None:
        super().__init__(name, children)
        self.index = 0
        self.skipped_count = 0

    def run(self) -> Ticking:
        count = len(self.children)
        if self.status != Status.RUNNING:
            self.skipped_count = 0
        while self.index < count:
            before = self.children[self.index].status
            result = yield from self.tick_index(self.index)
            if result == Status.RUNNING:
                return Status.RUNNING
            if result == self.stop_on:
                if self.restart_on_stop:
                    self.reset_children()
                    self.index = 0
                else:
                    self.reset_children(self.index + 1)
                return self.stop_on
            self.index += 1
            self.skipped_count += result == SKIPPED
            if self.asynchronous and result != SKIPPED and before != Status.RUNNING and self.index < count:
                return Status.RUNNING
        all_skipped = self.skipped_count == count
        self.index = self.skipped_count = 0
        return SKIPPED if all_skipped else Status.SUCCESS if self.stop_on == Status.FAILURE else Status.FAILURE

    def halted(self) -> None:
        if self.restart_on_stop:
            self.index = 0
        self.skipped_count = 0


class SequenceWithMemory(SequenceNode):
    """BehaviorTree.CPP ``SequenceWithMemory``: after a failure or a halt it resumes at the child that failed."""

    restart_on_stop = False
    asynchronous = True

    def restart_from(self) -> int:
        return self.index  # the children before it are not ticked again


class FallbackNode(SequenceNode):
    """BehaviorTree.CPP ``Fallback``: the first child that succeeds; a RUNNING child is ticked again."""

    stop_on = Status.SUCCESS


class ReactiveNode(Control):
    """BehaviorTree.CPP ``ReactiveSequence`` (``stop_on`` FAILURE) and ``ReactiveFallback`` (``stop_on`` SUCCESS).

    Every tick starts at the first child; a RUNNING child halts every other child (completed ones back to IDLE).
    """

    def __init__(self, name: str, children: Sequence[Behaviour] | None = None, *, fallback: bool = False) -> None:
        super().__init__(name, children)
        self.stop_on = Status.SUCCESS if fallback else Status.FAILURE
        self.otherwise = Status.FAILURE if fallback else Status.SUCCESS

    def run(self) -> Ticking:
        all_skipped = True
        for index, child in enumerate(self.children):
            result = yield from self.tick_index(index)
            all_skipped &= result == SKIPPED
            if result == Status.RUNNING:
                for other in self.children:
                    if other is not child:
                        reset(other)
                return Status.RUNNING
            if result == self.stop_on:
                self.reset_children()
                return self.stop_on
        return SKIPPED if all_skipped else self.otherwise


class ParallelNode(Control):
    """BehaviorTree.CPP ``Parallel``: ``success_count`` (default -1: all) and ``failure_count`` (default 1)."""

    def __init__(self, name: str, children: Sequence[Behaviour] | None = None, success_count: int = -1,
                 failure_count: int = 1) -> None:
        super().__init__(name, children)
        self.success_count, self.failure_count = success_count, failure_count
        self.completed: set[int] = set()
        self.successes = self.failures = 0

    @staticmethod
    def threshold(value: int, children: int) -> int:
        return max(children + value + 1, 0) if value < 0 else value

    def run(self) -> Ticking:
        count = len(self.children)
        needed = self.threshold(self.success_count, count)
        failing = self.threshold(self.failure_count, count)
        skipped = 0
        for index in range(count):
            if index not in self.completed:
                result = yield from self.tick_index(index)
                if result == SKIPPED:
                    skipped += 1
                elif result in (Status.SUCCESS, Status.FAILURE):
                    self.completed.add(index)
                    if result == Status.SUCCESS:
                        self.successes += 1
                    else:
                        self.failures += 1
            if self.successes >= needed or (self.success_count < 0 and self.successes + skipped >= needed):
                return self._done(Status.SUCCESS)
            if count - self.failures < needed or self.failures == failing:
                return self._done(Status.FAILURE)
        return SKIPPED if skipped == count else Status.RUNNING

    def _done(self, status: Status) -> Status:
        self.halted()
        for child in self.children:
            if child.status == Status.RUNNING:
                halt(child)
        return status

    def halted(self) -> None:
        self.completed.clear()
        self.successes = self.failures = 0


class IfThenElseNode(Control):
    """BehaviorTree.CPP ``IfThenElse``: the condition (first child) is ticked until it completes, then one branch."""

    def __init__(self, name: str, children: Sequence[Behaviour] | None = None) -> None:
        super().__init__(name, children)
        self.branch = 0

    def run(self) -> Ticking:
        if self.branch == 0:
            condition = yield from self.tick_index(0)
            if condition == Status.RUNNING:
                return Status.RUNNING
            if condition in (Status.SUCCESS, SKIPPED):
                self.branch = 1
            elif len(self.children) == 3:
                self.branch = 2
            else:
                return Status.FAILURE
        result = yield from self.tick_index(self.branch)
        if result == Status.RUNNING:
            return Status.RUNNING
        self.branch = 0
        return result

    def halted(self) -> None:
        self.branch = 0


class WhileDoElseNode(Control):
    """BehaviorTree.CPP ``WhileDoElse``: the condition is ticked every time; switching branch halts the other."""

    def run(self) -> Ticking:
        condition = yield from self.tick_index(0)
        if condition == Status.RUNNING:
            return Status.RUNNING
        if condition in (Status.SUCCESS, SKIPPED):
            if len(self.children) == 3:
                halt(self.children[2])
            result = yield from self.tick_index(1)
        elif len(self.children) == 3:
            halt(self.children[1])
            result = yield from self.tick_index(2)
        else:
            result = Status.FAILURE
        if result != Status.RUNNING:
            self.reset_children()
        return result


def make_control(kind: str, name: str, children: list[Behaviour], ports: dict[str, Any]) -> Control:
    """The composite for a BehaviorTree.CPP control node type (``ports`` already typed)."""
    if kind == "Sequence":
        return SequenceNode(name, children)
    if kind == "SequenceWithMemory":
        return SequenceWithMemory(name, children)
    if kind == "Fallback":
        return FallbackNode(name, children)
    if kind in ("AsyncSequence", "AsyncFallback"):
        node = SequenceNode(name, children) if kind == "AsyncSequence" else FallbackNode(name, children)
        node.asynchronous = True
        return node
    if kind in ("ReactiveSequence", "ReactiveFallback"):
        return ReactiveNode(name, children, fallback=kind == "ReactiveFallback")
    if kind == "Parallel":
        return ParallelNode(name, children, int(ports.get("success_count", -1)), int(ports.get("failure_count", 1)))
    if kind == "IfThenElse":
        return IfThenElseNode(name, children)
    if kind == "WhileDoElse":
        return WhileDoElseNode(name, children)
    raise ValueError(f"{kind} is not a control node")
