"""BehaviorTree.CPP v4's control nodes that choose a branch: IfThenElse ticks its condition only until it completes;
WhileDoElse ticks it on every tick and halts the branch it leaves; SwitchN ticks the child of the case equal to
``variable``; TryCatch (4.10) runs its last child when the others, as a Sequence, fail.
"""

from __future__ import annotations

from typing import Any

from aeroexec.trees.runtime.manifests import MANIFESTS
from aeroexec.trees.runtime.nodes.controls import Control
from aeroexec.trees.runtime.ports import NodeConfig, PortError
from aeroexec.trees.runtime.ticking import FAILURE, RUNNING, SKIPPED, SUCCESS, Result, TickError, halt, reset
from py_trees.behaviour import Behaviour


class IfThenElse(Control):
    """The condition (first child) is ticked until it completes, then one branch."""

    manifest = MANIFESTS["IfThenElse"]

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, children, config)
        self.branch = 0

    def run(self) -> Result:
        if self.branch == 0:
            condition = self.tick_index(0)
            if condition is RUNNING:
                return RUNNING
            if condition is SUCCESS or condition is SKIPPED:
                self.branch = 1
            elif len(self.children) == 3:
                self.branch = 2
            else:
                return FAILURE
        result = self.tick_index(self.branch)
        if result is RUNNING:
            return RUNNING
        self.branch = 0
        return result

    def halted(self) -> None:
        self.branch = 0


class WhileDoElse(Control):
    """The condition is ticked every time; switching branch halts the other."""

    manifest = MANIFESTS["WhileDoElse"]

    def run(self) -> Result:
        condition = self.tick_index(0)
        if condition is RUNNING:
            return RUNNING
        if condition is SUCCESS or condition is SKIPPED:
            if len(self.children) == 3:
                halt(self.children[2])
            result = self.tick_index(1)
        elif len(self.children) == 3:
            halt(self.children[1])
            result = self.tick_index(2)
        else:
            result = FAILURE
        if result is not RUNNING:
            self.reset_children()
        return result


class Switch(Control):
    """SwitchN: the child of the first ``case_i`` equal to ``variable`` (as text or as numbers), else the last."""

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, children, config)
        variable, *cases = self.manifest.ports  # variable, case_1 ... case_N
        self.cases = len(cases)
        self.variable = self.config.input(variable.name, self.manifest.ports)
        self.case_inputs = [self.config.input(case.name, self.manifest.ports) for case in cases]
        self.running: int | None = None

    def run(self) -> Result:
        chosen = self.cases
        variable = _case_text(self.variable)
        if variable is not None:
            for index, case in enumerate(self.case_inputs):
                value = _case_text(case)
                if value is not None and _equal(variable, value):
                    chosen = index
                    break
        if self.running is not None and self.running != chosen:
            halt(self.children[self.running])
        result = self.tick_index(chosen)
        if result is RUNNING:
            self.running = chosen
        else:
            self.running = None
            if result is not SKIPPED:
                for child in self.children:
                    if child.status is RUNNING:
                        reset(child)
        return result

    def halted(self) -> None:
        self.running = None


def _case_text(port: Any) -> str | None:
    """A case's text: a ``{key}`` nothing wrote matches nothing."""
    if port.key is not None and port.key not in port.board:
        return None
    return port.get() if port.given else None


def _equal(a: str, b: str) -> bool:
    if a == b:
        return True
    try:
        return abs(float(a) - float(b)) < 1e-9
    except ValueError:
        return False


class Switch2(Switch):
    manifest = MANIFESTS["Switch2"]


class Switch3(Switch):
    manifest = MANIFESTS["Switch3"]


class Switch4(Switch):
    manifest = MANIFESTS["Switch4"]


class Switch5(Switch):
    manifest = MANIFESTS["Switch5"]


class Switch6(Switch):
    manifest = MANIFESTS["Switch6"]


class TryCatch(Control):
    """BT.CPP 4.10's TryCatch: children 1..N-1 as a Sequence; when one fails the last child runs (its result is
    ignored) and the node fails. ``catch_on_halt``: a halt during the try-block runs the catch child too.

    As in 4.10, a node of the try-block that cannot tick (a script error, a port it cannot read) throws out of the
    whole tree: TryCatch catches failures, not exceptions. One deliberate difference: the catch child run by a halt
    (``catch_on_halt``) that cannot tick is recorded (``tree_error``) and the halt goes on, where BT.CPP's
    exception would leave the halt half done (a halt may come from the run ending, which must land the drone)."""

    manifest = MANIFESTS["TryCatch"]

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, children, config)
        self.catch_on_halt = self.config.input("catch_on_halt", self.manifest.ports)
        self.index, self.skipped_count, self.catching = 0, 0, False

    def run(self) -> Result:
        tries = len(self.children) - 1
        if self.status is not RUNNING:
            self.skipped_count, self.catching = 0, False
        while not self.catching and self.index < tries:
            result = self.tick_index(self.index)  # a node that cannot tick throws out of the tick, as in 4.10
            if result is RUNNING:
                return RUNNING
            if result is FAILURE:
                for child in self.children:
                    halt(child)
                self.index, self.catching = 0, True
                break
            self.index += 1
            self.skipped_count += result is SKIPPED
        if self.catching:
            result = self.tick_index(tries)
            if result is RUNNING:
                return RUNNING
            self.catching = False
            return FAILURE
        all_skipped = self.skipped_count == tries
        self.index = self.skipped_count = 0
        return SKIPPED if all_skipped else SUCCESS

    def halted(self) -> None:
        if not self.catching and self.status is RUNNING and self._catches_on_halt():
            for child in self.children[:-1]:
                halt(child)
            catch = self.children[-1]
            try:
                catch.stepper(catch)
            except TickError as error:  # a halt goes on: the error is recorded
                self.caught(error)
            halt(catch)
        self.index = self.skipped_count = 0
        self.catching = False

    def caught(self, error: TickError) -> None:
        context = self.config.context
        if context is not None:
            context.record("tree_error", f"{error} (the catch child of TryCatch {self.name}, run by its halt)",
                           node=getattr(error.node, "name", ""), line=getattr(error.node, "line", 0))

    def _catches_on_halt(self) -> bool:
        try:  # as BT.CPP's halt(): a port it cannot read is false
            return bool(self.catch_on_halt.get())
        except PortError:
            return False
