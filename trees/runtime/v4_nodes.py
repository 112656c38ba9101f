"""BehaviorTree.CPP v4's newer built-ins: ParallelAll, TryCatch (4.10), Sleep, LoopInt/LoopDouble/LoopString/LoopBool,
SkipUnlessUpdated, WaitValueUpdate and WasEntryUpdated, with BT.CPP's semantics (times on the engine clock).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from aeroexec.trees.node_types import bare_key
from aeroexec.trees.runtime.control import SKIPPED, Control, Result, halt, reset
from aeroexec.trees.runtime.decorators import Decorator
from aeroexec.trees.runtime.nodes import Leaf
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class ParallelAll(Control):
    """Ticks every child until all completed; FAILURE when at least ``max_failures`` failed (negative: n + 1 + v)."""

    def __init__(self, name: str, children: Sequence[Behaviour], max_failures: int = 1) -> None:
        super().__init__(name, children)
        count = len(self.children)
        self.threshold = max(count + max_failures + 1, 0) if max_failures < 0 else max_failures
        self.completed: set[int] = set()
        self.failures = 0

    def run(self) -> Result:
        skipped = 0
        for index in range(len(self.children)):
            if index in self.completed:
                continue
            result = self.tick_index(index)
            if result is SKIPPED:
                skipped += 1
            elif result in (Status.SUCCESS, Status.FAILURE):
                self.completed.add(index)
                self.failures += result is Status.FAILURE
        count = len(self.children)
        if skipped == count:
            return SKIPPED
        if skipped + len(self.completed) >= count:
            failed = self.failures >= self.threshold
            for child in self.children:
                halt(child)
            self.halted()
            return Status.FAILURE if failed else Status.SUCCESS
        return Status.RUNNING

    def halted(self) -> None:
        self.completed.clear()
        self.failures = 0


class TryCatch(Control):
    """BT.CPP 4.10's TryCatch: children 1..N-1 as a Sequence; when one fails the last child runs (its result is
    ignored) and the node fails. ``catch_on_halt``: a halt during the try-block runs the catch child too."""

    def __init__(self, name: str, children: Sequence[Behaviour], catch_on_halt: bool = False) -> None:
        super().__init__(name, children)
        self.catch_on_halt = catch_on_halt
        self.index, self.skipped_count, self.catching = 0, 0, False

    def run(self) -> Result:
        tries = len(self.children) - 1
        if self.status is not Status.RUNNING:
            self.skipped_count, self.catching = 0, False
        while not self.catching and self.index < tries:
            result = self.tick_index(self.index)
            if result is Status.RUNNING:
                return Status.RUNNING
            if result is Status.FAILURE:
                for child in self.children:
                    halt(child)
                self.index, self.catching = 0, True
                break
            self.index += 1
            self.skipped_count += result is SKIPPED
        if self.catching:
            result = self.tick_index(tries)
            if result is Status.RUNNING:
                return Status.RUNNING
            self.catching = False
            return Status.FAILURE
        all_skipped = self.skipped_count == tries
        self.index = self.skipped_count = 0
        return SKIPPED if all_skipped else Status.SUCCESS

    def halted(self) -> None:
        if self.catch_on_halt and not self.catching and self.status is Status.RUNNING:
            for child in self.children[:-1]:
                halt(child)
            catch = self.children[-1]
            catch.step()
            halt(catch)
        self.index = self.skipped_count = 0
        self.catching = False


class Sleep(Leaf):
    """RUNNING until ``seconds`` of engine time passed since it started, then SUCCESS."""

    def __init__(self, name: str, seconds: float, context: Any, blackboard: Any, source: Any = None) -> None:
        super().__init__(name, context, blackboard, source)
        self.seconds = seconds
        self.started_at = 0.0

    def initialise(self) -> None:
        self.started_at = self.context.now()

    def update(self) -> Status:
        if self.seconds <= 0 or self.context.now() - self.started_at >= self.seconds - 1e-9:
            return Status.SUCCESS
        return Status.RUNNING


def queue_items(text: str, kind: Callable[[str], Any]) -> list[Any]:
    """A LoopX queue written as text: ``1;2;3``."""
    return [kind(part.strip()) for part in text.split(";") if part.strip()]


def _bool(text: str) -> bool:
    return text.strip().lower() in ("true", "1")


LOOP_TYPES: dict[str, Callable[[str], Any]] = {"LoopInt": int, "LoopDouble": float, "LoopString": str,
                                               "LoopBool": _bool}


class Loop(Decorator):
    """LoopX: pops the next value of ``queue`` into ``value`` and ticks the child with it, while the queue has items;
    FAILURE when the child fails; ``if_empty`` (SUCCESS) when the queue is empty at the start."""

    def __init__(self, name: str, child: Behaviour, kind: str, ports: dict[str, str], board: Any) -> None:
        super().__init__(name, child)
        self.convert, self.board = LOOP_TYPES[kind], board
        self.source_key = bare_key(ports.get("queue", ""))
        self.static = None if self.source_key is not None else ports.get("queue", "")
        self.value_key = bare_key(ports.get("value", "")) or ports.get("value", "").strip()
        empty = ports.get("if_empty", "SUCCESS").strip()
        self.if_empty = SKIPPED if empty == "SKIPPED" else Status[empty]
        self.queue: list[Any] = []
        self.child_running = False

    def run(self) -> Result:
        popped = False
        if self.status is not Status.RUNNING:
            self.child_running = False
            if self.static is not None:
                self.queue = queue_items(self.static, self.convert)
        if not self.child_running:
            if self.source_key is not None:
                held = self.board.get(self.source_key)
                self.queue = (queue_items(held, self.convert) if isinstance(held, str)
                              else held if isinstance(held, list) else [])
            if self.queue:
                self.board[self.value_key] = self.queue.pop(0)
                popped = True
        if not popped and not self.child_running:
            return self.if_empty
        result = self.decorated.step()
        self.child_running = result is Status.RUNNING
        if result in (Status.SUCCESS, Status.FAILURE):
            reset(self.decorated)
        return Status.FAILURE if result is Status.FAILURE else Status.RUNNING

    def halted(self) -> None:
        self.child_running = False


class EntryUpdated(Decorator):
    """SkipUnlessUpdated (SKIPPED) and WaitValueUpdate (RUNNING): the child runs only when ``entry`` was written
    since the node last looked; a child RUNNING is ticked on regardless."""

    def __init__(self, name: str, child: Behaviour, entry: str, board: Any, otherwise: Any) -> None:
        super().__init__(name, child)
        self.key, self.board, self.otherwise = bare_key(entry) or entry.strip(), board, otherwise
        self.seen = 0
        self.executing = False

    def run(self) -> Result:
        if not self.executing:
            current = self.board.version(self.key)
            previous, self.seen = self.seen, current
            if current == 0 or current == previous:
                return self.otherwise
        result = self.decorated.step()
        self.executing = result is Status.RUNNING
        return result

    def halted(self) -> None:
        self.executing = False


class WasEntryUpdated(Leaf):
    """SUCCESS when ``entry`` was written since this node last looked, else FAILURE."""

    def __init__(self, name: str, entry: str, context: Any, blackboard: Any, source: Any = None) -> None:
        super().__init__(name, context, blackboard, source)
        self.key = bare_key(entry) or entry.strip()
        self.seen = 0

    def update(self) -> Status:
        current = self.blackboard.version(self.key)
        previous, self.seen = self.seen, current
        return Status.SUCCESS if current and current != previous else Status.FAILURE
