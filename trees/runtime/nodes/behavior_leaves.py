"""The engine's behavior leaves: a catalog behavior with its arguments as ports, and AskBehavior, which writes a
deliberative behavior's result to the blackboard.

A behavior leaf asks the coordinator to activate its behavior on its first tick and is RUNNING until the
behavior's event: GOAL_ACHIEVED -> SUCCESS, any other outcome (or a refused activation) -> FAILURE. A recurrent
behavior has no goal: its leaf stays RUNNING, or succeeds once the behavior is active with
``_wait_for_completion="false"`` (Aerostack's dialect; the behavior then runs on until stopped). A leaf halted
while RUNNING inhibits the behavior it started (INTERRUPTED). Ports may read the blackboard with ``{key}``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from aeroexec.engine.catalog.descriptors import RECURRENT
from aeroexec.engine.events import Outcome
from aeroexec.trees.model import WAIT_FOR_COMPLETION
from aeroexec.trees.ports import MissingKey, request_from_ports
from aeroexec.trees.runtime.manifests import MANIFESTS
from aeroexec.trees.runtime.nodes.actions import Leaf
from aeroexec.trees.runtime.ports import NodeConfig
from py_trees.common import Status


class BehaviorLeaf(Leaf):
    """A catalog behavior with its arguments as ports (not in the registration table: the catalog names them)."""

    skip_ports: tuple[str, ...] = ()

    def __init__(self, name: str, config: NodeConfig, behavior: str | None = None) -> None:
        super().__init__(name, config)
        ports: Mapping[str, str] = config.model.ports
        self.behavior = behavior if behavior is not None else config.model.type
        self.ports = dict(ports)
        self.wait = ports.get(WAIT_FOR_COMPLETION, "true").strip().lower() not in ("false", "0", "no")
        self.activation: Any = None
        self.ended: tuple[Outcome | None, str, Any] | None = None
        self._run = 0

    def initialise(self) -> None:
        self._run += 1
        self.activation, self.ended = None, None

    def update(self) -> Status:
        if self.activation is None and self.ended is None:
            return self.start()
        return self.progress()

    def start(self) -> Status:
        engine = self.context.engine
        descriptor = engine.catalog.behavior(self.behavior)
        if descriptor is None:
            return self.error(f"The behavior {self.behavior} does not exist")
        try:
            arguments, options = request_from_ports(descriptor, self.ports, self.blackboard, self.skip_ports)
        except MissingKey as missing:
            return self.error(f"{self.behavior}: {missing}")
        run = self._run
        result = engine.coordinator.activate(self.behavior, arguments, timeout=options.get("timeout"),
                                             source="mission", on_end=lambda o, m, r: self.on_end(run, o, m, r))
        if not result.accepted:
            self.ended = self.ended or (result.outcome, result.message, None)
            self.feedback_message = result.message
            return Status.SUCCESS if result.outcome is Outcome.GOAL_ACHIEVED else Status.FAILURE
        self.activation = result.activation
        self.context.started.append(result.activation)
        return self.progress()

    def progress(self) -> Status:
        if self.ended is not None:
            outcome, message, value = self.ended
            self.feedback_message = f"{outcome}: {message}" if message else str(outcome)
            return self.finished(value) if outcome is Outcome.GOAL_ACHIEVED else Status.FAILURE
        if not self.wait and self.activation.category == RECURRENT and self.activation.running:
            return Status.SUCCESS
        return Status.RUNNING

    def finished(self, value: Any) -> Status:
        return Status.SUCCESS

    def on_end(self, run: int, outcome: Outcome, message: str, value: Any) -> None:
        if run == self._run and self.ended is None:
            self.ended = (outcome, message, value)

    def terminate(self, new_status: Status) -> None:
        if new_status != Status.INVALID or self.status != Status.RUNNING or self.activation is None:
            return
        coordinator = self.context.engine.coordinator
        self._run += 1  # the INTERRUPTED event belongs to this halt, not to a later run
        if coordinator.active().get(self.behavior) is self.activation:
            coordinator.stop(self.behavior, f"halted by the behavior tree ({self.where})")


class AskBehavior(BehaviorLeaf):
    """``<AskBehavior behavior="GENERATE_PATH_FREE_OF_OBSTACLES" DESTINATION="..." result="{path}"/>``: the
    behavior's other ports are its arguments."""

    manifest = MANIFESTS["AskBehavior"]
    skip_ports = ("behavior", "result")

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config, config.model.ports.get("behavior", "").strip())
        self.key = config.output("result") or "result"

    def finished(self, value: Any) -> Status:
        self.blackboard[self.key] = value
        return Status.SUCCESS
