"""BehaviorTree.CPP's script and blackboard nodes: Script, ScriptCondition, SetBlackboard, UnsetBlackboard,
the Precondition decorator and Switch2..Switch6.

A script that fails while it runs (a key not written, a type mismatch) makes its node FAILURE and records a
``tree_error`` with the node's place (BT.CPP throws out of the tick instead).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from aeroexec.trees.node_types import bare_key
from aeroexec.trees.runtime.control import SKIPPED, Control, Result, halt, reset
from aeroexec.trees.runtime.decorators import Decorator
from aeroexec.trees.runtime.nodes import Leaf
from aeroexec.trees.script import ScriptError, compile_script, truth
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class ScriptLeaf(Leaf):
    """Script (SUCCESS once run) and ScriptCondition (SUCCESS when the script's value is true)."""

    def __init__(self, name: str, code: str, condition: bool, context: Any, blackboard: Any, source: Any = None):
        super().__init__(name, context, blackboard, source)
        self.script, self.condition = compile_script(code), condition

    def update(self) -> Status:
        try:
            value = self.script.run(self.blackboard, self.context.belief_holds)
        except ScriptError as error:
            return self.error(str(error))
        return Status.SUCCESS if not self.condition or truth(value) else Status.FAILURE


class SetBlackboard(Leaf):
    """``output_key`` gets ``value`` (a ``{key}`` value copies that key's value)."""

    def __init__(self, name: str, ports: dict[str, str], context: Any, blackboard: Any, source: Any = None):
        super().__init__(name, context, blackboard, source)
        self.key = bare_key(ports.get("output_key", "")) or ports.get("output_key", "").strip()
        self.value = ports.get("value", "")

    def update(self) -> Status:
        source = bare_key(self.value)
        if source is not None:
            if source not in self.blackboard:
                return self.error(f"Can't find the port referred by [value]: {{{source}}}")
            self.blackboard[self.key] = self.blackboard[source]
        else:
            self.blackboard[self.key] = self.value
        return Status.SUCCESS


class UnsetBlackboard(Leaf):
    def __init__(self, name: str, key: str, context: Any, blackboard: Any, source: Any = None):
        super().__init__(name, context, blackboard, source)
        self.key = key.strip()

    def update(self) -> Status:
        self.blackboard.pop(self.key, None)
        return Status.SUCCESS


class Precondition(Decorator):
    """Ticks its child once the ``if`` script holds, until the child completes; otherwise answers ``else``
    (FAILURE)."""

    def __init__(self, name: str, child: Behaviour, code: str, otherwise: str, board: Any, context: Any):
        super().__init__(name, child)
        self.script, self.board, self.context = compile_script(code), board, context
        self.otherwise = SKIPPED if otherwise.strip() == "SKIPPED" else Status[otherwise.strip() or "FAILURE"]
        self.running = False

    def run(self) -> Result:
        if not self.running:
            try:
                self.running = self.script.holds(self.board, self.context.belief_holds)
            except ScriptError as error:
                where = getattr(getattr(self, "source", None), "where", self.name)
                self.context.record("tree_error", f"{where}: {error}", node=self.name)
                return Status.FAILURE
        if not self.running:
            return self.otherwise
        result = self.decorated.step()
        if result in (Status.SUCCESS, Status.FAILURE):  # as BT.CPP: a skipped child, or a halt, keeps it open
            self.running = False
        return result


class Switch(Control):
    """SwitchN: the child of the first ``case_i`` equal to ``variable`` (as text or as numbers), else the last."""

    def __init__(self, name: str, children: Sequence[Behaviour], ports: dict[str, str], board: Any):
        super().__init__(name, children)
        self.ports, self.board = ports, board
        self.running: int | None = None

    def _read(self, port: str) -> str | None:
        text = self.ports.get(port)
        key = bare_key(text or "")
        if key is not None:
            return None if key not in self.board else str(self.board[key])
        return text

    def run(self) -> Result:
        cases = len(self.children) - 1
        chosen = cases
        variable = self._read("variable")
        if variable is not None:
            for index in range(cases):
                value = self._read(f"case_{index + 1}")
                if value is not None and _equal(variable, value):
                    chosen = index
                    break
        if self.running is not None and self.running != chosen:
            halt(self.children[self.running])
        result = self.tick_index(chosen)
        if result is Status.RUNNING:
            self.running = chosen
        else:
            self.running = None
            if result is not SKIPPED:
                for child in self.children:
                    reset(child) if child.status is Status.RUNNING else None
        return result

    def halted(self) -> None:
        self.running = None


def _equal(a: str, b: str) -> bool:
    if a == b:
        return True
    try:
        return abs(float(a) - float(b)) < 1e-9
    except ValueError:
        return False
