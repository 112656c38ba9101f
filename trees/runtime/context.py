"""What the nodes of one tree run share: the engine, the behaviors the tree started, and the scripts and belief
expressions of its pre- and post-conditions turned into functions."""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from aeroexec.beliefs import BeliefError
from aeroexec.trees.model import TreeNode
from aeroexec.trees.ports import MissingKey, substitute
from aeroexec.trees.runtime.ticking import TickError
from aeroexec.trees.script import ScriptError, compile_script

logger = logging.getLogger(__name__)


@dataclass
class TreeContext:
    """What the leaves of one tree run share: the engine and the activations they started."""

    engine: Any  # aeroexec.engine.engine.Engine (duck-typed: coordinator, memory, catalog, log, now)
    started: list[Any] = field(default_factory=list)  # coordinator Activations, in order
    reported: set[str] = field(default_factory=set)

    def now(self) -> float:
        return self.engine.now()

    def record(self, kind: str, detail: str, once: bool = False, **data: Any) -> None:
        """Record an event (``once``: only the first time this detail occurs, for checks made every tick)."""
        if once:
            if detail in self.reported:
                return
            self.reported.add(detail)
        self.engine.log.record(kind, detail=detail, **data)

    def belief_check(self, text: str, blackboard: Mapping[str, Any], where: str) -> Callable[[], bool]:
        """A function telling whether a belief expression (``{key}`` read now) holds; an error is false and logged."""
        def holds() -> bool:
            try:
                return self.engine.memory.holds(substitute(text, blackboard, as_term=True))
            except (BeliefError, MissingKey) as error:
                self.record("tree_error", f"{where}: {text}: {error}", once=True)
                return False

        return holds

    def belief_holds(self, text: str) -> bool:
        """Whether a belief expression holds now (scripts' ``belief("...")``)."""
        return self.engine.memory.holds(text)

    def condition(self, model: TreeNode, attribute: str, blackboard: Any) -> Callable[[], bool]:
        """A pre-condition attribute of ``model`` as a function: a script (BT.CPP's meaning), or else, read with a
        warning, the belief expression aeroexec took there before (``<CheckBelief>`` or ``belief("...")`` is the
        portable way). A script that fails raises :class:`TickError`, as BT.CPP throws."""
        text, where = model.ports[attribute], f"{model.where} {attribute}"
        try:
            script = compile_script(text)
        except ScriptError:
            logger.warning("%s: %r is no script: read as a belief expression (write belief(\"...\") instead)",
                           where, text)
            return self.belief_check(text, blackboard, where)

        def holds() -> bool:
            try:
                return script.holds(blackboard, self.belief_holds)
            except (ScriptError, BeliefError) as error:
                raise TickError(model, f"{attribute}: {error}") from None

        return holds

    def action(self, model: TreeNode, attribute: str, blackboard: Any) -> Callable[[], None]:
        """A post-condition attribute of ``model`` (``_onSuccess``...) as a function running its script (raises
        :class:`TickError`)."""
        script = compile_script(model.ports[attribute])

        def run() -> None:
            try:
                script.run(blackboard, self.belief_holds)
            except (ScriptError, BeliefError) as error:
                raise TickError(model, f"{attribute}: {error}") from None

        return run

    def stop_started(self, reason: str) -> None:
        """Stop every behavior this tree started that is still active (INTERRUPTED)."""
        coordinator = self.engine.coordinator
        for activation in reversed(self.started):
            if coordinator.active().get(activation.name) is activation:
                coordinator.stop(activation.name, reason)
        self.started.clear()
