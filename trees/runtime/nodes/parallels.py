"""BehaviorTree.CPP v4's parallel control nodes: Parallel ticks every child that has not completed and succeeds once
``success_count`` children succeed (negative: all but ``-1 - n``), fails once ``failure_count`` fail or success
became impossible; completing halts the running children. ParallelAll ticks every child until all completed.
"""

from __future__ import annotations

from aeroexec.trees.runtime.manifests import MANIFESTS
from aeroexec.trees.runtime.nodes.controls import Control
from aeroexec.trees.runtime.ports import NodeConfig
from aeroexec.trees.runtime.ticking import FAILURE, RUNNING, SKIPPED, SUCCESS, Result, TickError, halt
from py_trees.behaviour import Behaviour
from py_trees.common import Status


def _threshold(value: int, children: int) -> int:
    return max(children + value + 1, 0) if value < 0 else value


class Parallel(Control):
    """Succeeds once ``success_count`` children succeed (default -1: all), fails once ``failure_count`` failed
    (default 1) or success became impossible."""

    manifest = MANIFESTS["Parallel"]
    in_order = True

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, children, config)
        self.success_count = self.config.input("success_count", self.manifest.ports)
        self.failure_count = self.config.input("failure_count", self.manifest.ports)
        self.completed: set[int] = set()
        self.successes = self.failures = 0

    def run(self) -> Result:
        count = len(self.children)
        success_count = self.success_count.get()
        needed = _threshold(success_count, count)
        failing = _threshold(self.failure_count.get(), count)
        if count < needed or count < failing:
            raise TickError(self.config.model, "Number of children is less than threshold. Can never "
                                               f"{'succeed' if count < needed else 'fail'}.")
        skipped = 0
        for index in range(count):
            if index not in self.completed:
                result = self.tick_index(index)
                if result is SKIPPED:
                    skipped += 1
                elif result is SUCCESS or result is FAILURE:
                    self.completed.add(index)
                    if result is SUCCESS:
                        self.successes += 1
                    else:
                        self.failures += 1
            if self.successes >= needed or (success_count < 0 and self.successes + skipped >= needed):
                return self._done(SUCCESS)
            if count - self.failures < needed or self.failures == failing:
                return self._done(FAILURE)
        return SKIPPED if skipped == count else RUNNING

    def _done(self, status: Status) -> Status:
        self.halted()
        for child in self.children:
            if child.status is RUNNING:
                halt(child)
        return status

    def halted(self) -> None:
        self.completed.clear()
        self.successes = self.failures = 0


class ParallelAll(Control):
    """Ticks every child until all completed; FAILURE when at least ``max_failures`` failed (negative: n + 1 + v)."""

    manifest = MANIFESTS["ParallelAll"]
    in_order = True

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, children, config)
        self.max_failures = self.config.input("max_failures", self.manifest.ports)
        self.completed: set[int] = set()
        self.failures = 0

    def run(self) -> Result:
        skipped = 0
        count = len(self.children)
        threshold = _threshold(self.max_failures.get(), count)
        if count < threshold:
            raise TickError(self.config.model, "Number of children is less than threshold. Can never fail.")
        for index in range(count):
            if index in self.completed:
                continue
            result = self.tick_index(index)
            if result is SKIPPED:
                skipped += 1
            elif result is SUCCESS or result is FAILURE:
                self.completed.add(index)
                self.failures += result is FAILURE
        if skipped == count:
            return SKIPPED
        if skipped + len(self.completed) >= count:
            failed = self.failures >= threshold
            for child in self.children:
                halt(child)
            self.halted()
            return FAILURE if failed else SUCCESS
        return RUNNING

    def halted(self) -> None:
        self.completed.clear()
        self.failures = 0
