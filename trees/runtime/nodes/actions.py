"""BehaviorTree.CPP v4's built-in leaves (actions and conditions), one class per node name: AlwaysSuccess,
AlwaysFailure, Script, ScriptCondition, SetBlackboard, UnsetBlackboard, Sleep and WasEntryUpdated; and
:class:`Leaf`, the base of every leaf, the engine's included.

A script that fails while it runs (a variable nothing wrote, a type mismatch) raises :class:`TickError` out of
the tick, naming the node, as BT.CPP throws: the run fails (a TryCatch around it too, as in 4.10).
"""

from __future__ import annotations

from aeroexec.trees.conversions import ConversionError
from aeroexec.trees.runtime.manifests import MANIFESTS
from aeroexec.trees.runtime.ports import NodeConfig
from aeroexec.trees.runtime.ticking import FAILURE, RUNNING, SUCCESS, Node, TickError, kept
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
    manifest = MANIFESTS["AlwaysSuccess"]
    result = SUCCESS
    __slots__ = ("_result",)  # read at every tick: in a slot

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self._result = self.result

    def update(self) -> Status:
        return self.result

    def step(self) -> Status:  # ticking.kept, inlined: constants are ticked often
        status, tree = self._result, self.tree
        if status is not self.status:
            tree.changed.append(self)
            self.status = status
        self.ticked = tree.number
        if tree.visits is not None:
            tree.visits.append((self, status))
        return status


class AlwaysFailure(AlwaysSuccess):
    manifest = MANIFESTS["AlwaysFailure"]
    result = FAILURE


class Script(Leaf):
    """Runs its script; SUCCESS."""

    manifest = MANIFESTS["Script"]
    condition = False

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.script = compile_script(config.model.ports.get("code", ""))

    def update(self) -> Status:
        try:
            value = self.script.run(self.blackboard, self.context.belief_holds)
            return SUCCESS if not self.condition or truth(value) else FAILURE
        except ScriptError as error:
            raise TickError(self.source, str(error)) from None


class ScriptCondition(Script):
    """SUCCESS when its script's value is true, else FAILURE."""

    manifest = MANIFESTS["ScriptCondition"]
    condition = True


class SetBlackboard(Leaf):
    """``output_key`` gets ``value`` (a ``{key}`` value copies that key's value; FAILURE when it holds none, as in
    BT.CPP); text written to a typed entry is converted to its type; text over an entry a script created leaves it
    empty, as BT.CPP's does (no converter for an entry of no type: the next read of it fails), and over such an
    emptied entry throws (``Blackboard.text_over_untyped``)."""

    manifest = MANIFESTS["SetBlackboard"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.key = config.output("output_key")
        self.value = config.input("value", self.manifest.ports)

    def update(self) -> Status:
        source = self.value.key
        if source is not None:
            if source not in self.blackboard:  # BT.CPP: the entry holds no value yet
                self.feedback_message = f"{{{source}}} holds no value"
                return FAILURE
            value = self.blackboard[source]
        else:
            value = self.value.value if self.value.value is not None else ""
            done = self.blackboard.text_over_untyped(self.key)  # over an entry a script made: as BT.CPP
            if done == "empty":
                return SUCCESS
            if done == "refuse":
                raise TickError(self.source, f"Can't convert string [{value}] to type [BT::Any]")
        try:
            self.blackboard[self.key] = value
        except ConversionError as error:
            raise TickError(self.source, f"Can't convert string [{value}] to type "
                                         f"[{self.blackboard.type_of(self.key)}]: {error}") from None
        return SUCCESS


class UnsetBlackboard(Leaf):
    """Removes the entry ``key``."""

    manifest = MANIFESTS["UnsetBlackboard"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.key = config.model.ports.get("key", "").strip()

    def update(self) -> Status:
        self.blackboard.pop(self.key, None)
        return SUCCESS


class Sleep(Leaf):
    """RUNNING until ``msec`` of engine time passed since it started, then SUCCESS."""

    manifest = MANIFESTS["Sleep"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.msec = config.input("msec", self.manifest.ports)
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

    manifest = MANIFESTS["WasEntryUpdated"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.key = config.output("entry")
        self.seen = 0

    def update(self) -> Status:
        current = self.blackboard.version(self.key)
        previous, self.seen = self.seen, current
        return SUCCESS if current and current != previous else FAILURE

