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
from collections.abc import Sequence
from typing import Any

import py_trees
from aeroexec.trees.runtime.ticking import (
    INVALID,
    RUNNING,
    SKIPPED,
    SUCCESS,
    Node,
    Result,
    halt,
    reset,
    result_of,
    status_name,
)
from py_trees.behaviour import Behaviour
from py_trees.common import Status

__all__ = ["SKIPPED", "Control", "Result", "halt", "make_control", "reset", "result_of", "status_name"]


class Control(Node, py_trees.composites.Composite):
    """A composite whose ``run()`` decides its result from its children, BehaviorTree.CPP style."""

    def __init__(self, name: str, children: Sequence[Behaviour] | None = None) -> None:
        super().__init__(name, list(children or []))
        self.skipped = False

    @abc.abstractmethod
    def run(self) -> Result:
        """One tick of this control node: its result (every control node says how it ticks)."""

    def step(self) -> Result:
        old, old_skipped = self.status, self.skipped
        if old is not RUNNING:
            # starting again: the children it does not tick again are shown IDLE once the tick ends (those it
            # ticks show their new status)
            self.tree.stale.append((self, self.restart_from()))
            if self.initialises:
                self.initialise()
        result = self.run()
        if result is RUNNING:
            status, skipped = result, False
        else:
            status, skipped = (SUCCESS, True) if result is SKIPPED else (result, False)
            self.terminate(status)
        tree = self.tree  # Node.settle, inlined: every tick goes through control nodes
        if status is not old or skipped is not old_skipped:
            tree.changed.append(self)
        self.status, self.skipped, self.ticked = status, skipped, tree.number
        if tree.visits is not None:
            tree.visits.append((self, result))
        return result

    def restart_from(self) -> int:
        """The first child reset when the node starts again (the rest keep their status for display)."""
        return 0

    def reset_children(self, start: int = 0) -> None:
        """Halt the running children from ``start`` on."""
        children = self.children
        for index in range(start, len(children)):
            if children[index].status is RUNNING:
                children[index].stop(INVALID)

    def tick_index(self, index: int) -> Result:
        child = self.current_child = self.children[index]
        return child.step()  # type: ignore[attr-defined]

    def terminate(self, new_status: Status) -> None:
        if new_status is INVALID:
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

    def run(self) -> Result:
        children = self.children
        count = len(children)
        if self.status is not RUNNING:
            self.skipped_count = 0
        index, stop_on, asynchronous = self.index, self.stop_on, self.asynchronous
        while index < count:
            child = children[index]
            before = child.status
            result = child.step()
            if result is RUNNING:
                self.index, self.current_child = index, child
                return RUNNING
            if result is stop_on:
                self.index, self.current_child = index, child
                if self.restart_on_stop:
                    self.reset_children()
                    self.index = 0
                else:
                    self.reset_children(index + 1)
                return stop_on
            index += 1
            if result is SKIPPED:
                self.skipped_count += 1
            elif asynchronous and before is not RUNNING and index < count:
                self.index, self.current_child = index, child
                return RUNNING
        self.current_child = children[-1] if children else None
        all_skipped = self.skipped_count == count
        self.index = self.skipped_count = 0
        return SKIPPED if all_skipped else Status.SUCCESS if stop_on is Status.FAILURE else Status.FAILURE

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

    def run(self) -> Result:
        all_skipped = True
        for index, child in enumerate(self.children):
            result = self.tick_index(index)
            all_skipped &= result is SKIPPED
            if result is Status.RUNNING:
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

    def run(self) -> Result:
        count = len(self.children)
        needed = self.threshold(self.success_count, count)
        failing = self.threshold(self.failure_count, count)
        skipped = 0
        for index in range(count):
            if index not in self.completed:
                result = self.tick_index(index)
                if result is SKIPPED:
                    skipped += 1
                elif result in (Status.SUCCESS, Status.FAILURE):
                    self.completed.add(index)
                    if result is Status.SUCCESS:
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
            if child.status is Status.RUNNING:
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

    def run(self) -> Result:
        if self.branch == 0:
            condition = self.tick_index(0)
            if condition is Status.RUNNING:
                return Status.RUNNING
            if condition in (Status.SUCCESS, SKIPPED):
                self.branch = 1
            elif len(self.children) == 3:
                self.branch = 2
            else:
                return Status.FAILURE
        result = self.tick_index(self.branch)
        if result is Status.RUNNING:
            return Status.RUNNING
        self.branch = 0
        return result

    def halted(self) -> None:
        self.branch = 0


class WhileDoElseNode(Control):
    """BehaviorTree.CPP ``WhileDoElse``: the condition is ticked every time; switching branch halts the other."""

    def run(self) -> Result:
        condition = self.tick_index(0)
        if condition is Status.RUNNING:
            return Status.RUNNING
        if condition in (Status.SUCCESS, SKIPPED):
            if len(self.children) == 3:
                halt(self.children[2])
            result = self.tick_index(1)
        elif len(self.children) == 3:
            halt(self.children[1])
            result = self.tick_index(2)
        else:
            result = Status.FAILURE
        if result is not Status.RUNNING:
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
