"""BehaviorTree.CPP v4's built-in leaves (actions and conditions), one class per node name: AlwaysSuccess,
AlwaysFailure, Script, ScriptCondition, SetBlackboard, UnsetBlackboard, Sleep and WasEntryUpdated; and
:class:`Leaf`, the base of every leaf, the engine's included.

A script that fails while it runs (a key not written, a type mismatch) makes its node FAILURE and records a
``tree_error`` with the node's place (BT.CPP throws out of the tick instead).
"""

from __future__ import annotations

from aeroexec.trees.runtime.ports import ANY, STRING, UNSIGNED, BidirectionalPort, InputPort, NodeConfig
from aeroexec.trees.runtime.ticking import FAILURE, RUNNING, SUCCESS, Node, kept
from aeroexec.trees.script import ScriptError, compile_script, truth
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class Leaf(Node, Behaviour):
    """A leaf built from a model node: ``source`` is the node (file, line), ``blackboard`` its scope."""

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name)
        self.config = config
        self.context, self.blackboard, self.source = config.context, config.blackboard, config.model

    @classmethod
    def build(cls, config: NodeConfig, children: list[Behaviour]) -> Behaviour:
        return cls(config.model.name, config)

    def step(self) -> Status:
        """py_trees' leaf tick in one call: ``initialise`` when not RUNNING, ``update``, ``terminate`` when done."""
        old = self.status
        if old is not RUNNING and self.initialises:
            self.initialise()
        status = self.update()
        if status is not RUNNING:
            self.terminate(status)
        return kept(self, status)

    @property
    def where(self) -> str:
        return getattr(self.source, "where", "") or self.name

    def error(self, message: str) -> Status:
        self.feedback_message = message
        self.context.record("tree_error", f"{self.where}: {message}", node=self.name)
        return FAILURE


class AlwaysSuccess(Leaf):
    result = SUCCESS

    def update(self) -> Status:
        return self.result

    def step(self) -> Status:
        return kept(self, self.result)


class AlwaysFailure(AlwaysSuccess):
    result = FAILURE


class Script(Leaf):
    """Runs its script; SUCCESS."""

    ports = (InputPort("code", STRING, required=True, description="the script"),)
    condition = False

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.script = compile_script(config.model.ports.get("code", ""))

    def update(self) -> Status:
        try:
            value = self.script.run(self.blackboard, self.context.belief_holds)
        except ScriptError as error:
            return self.error(str(error))
        return SUCCESS if not self.condition or truth(value) else FAILURE


class ScriptCondition(Script):
    """SUCCESS when its script's value is true, else FAILURE."""

    condition = True


class SetBlackboard(Leaf):
    """``output_key`` gets ``value`` (a ``{key}`` value copies that key's value)."""

    ports = (InputPort("value", ANY, required=True, description="the value to write"),
             BidirectionalPort("output_key", ANY, "the blackboard entry it writes", required=True))

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.key = config.output("output_key")
        self.value = config.input("value", self.ports)

    def update(self) -> Status:
        source = self.value.key
        if source is not None:
            if source not in self.blackboard:
                return self.error(f"Can't find the port referred by [value]: {{{source}}}")
            self.blackboard[self.key] = self.blackboard[source]
        else:
            self.blackboard[self.key] = self.value.value if self.value.value is not None else ""
        return SUCCESS


class UnsetBlackboard(Leaf):
    """Removes the entry ``key``."""

    ports = (InputPort("key", STRING, required=True, description="the entry to remove"),)

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.key = config.model.ports.get("key", "").strip()

    def update(self) -> Status:
        self.blackboard.pop(self.key, None)
        return SUCCESS


class Sleep(Leaf):
    """RUNNING until ``msec`` of engine time passed since it started, then SUCCESS."""

    ports = (InputPort("msec", UNSIGNED, required=True, description="milliseconds to wait"),)

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.msec = config.input("msec", self.ports)
        self.seconds = 0.0
        self.started_at = 0.0

    def initialise(self) -> None:
        self.started_at, self.seconds = self.context.now(), self.msec.get() / 1000.0

    def update(self) -> Status:
        if self.seconds <= 0 or self.context.now() - self.started_at >= self.seconds - 1e-9:
            return SUCCESS
        return RUNNING


class WasEntryUpdated(Leaf):
    """SUCCESS when ``entry`` was written since this node last looked, else FAILURE."""

    ports = (InputPort("entry", ANY, required=True, description="the blackboard entry to watch"),)

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.key = config.output("entry")
        self.seen = 0

    def update(self) -> Status:
        current = self.blackboard.version(self.key)
        previous, self.seen = self.seen, current
        return SUCCESS if current and current != previous else FAILURE

