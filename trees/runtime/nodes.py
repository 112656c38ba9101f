"""Leaves that talk to the engine: catalog behaviors, belief conditions and queries, deliberative results, belief edits.

A behavior leaf asks the coordinator to activate its behavior on its first tick and is RUNNING until the
behavior's event: GOAL_ACHIEVED -> SUCCESS, any other outcome (or a refused activation) -> FAILURE. A recurrent
behavior has no goal: its leaf stays RUNNING, or succeeds once the behavior is active with
``_wait_for_completion="false"`` (Aerostack's dialect; the behavior then runs on until stopped). A leaf halted
while RUNNING inhibits the behavior it started (INTERRUPTED). Belief expressions may read the blackboard with
``{key}``; QueryBelief writes each variable it unifies (``?P`` -> key ``P``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from aeroexec.beliefs import BeliefError, parse_belief, to_python
from aeroexec.engine.catalog.descriptors import RECURRENT
from aeroexec.engine.events import Outcome
from aeroexec.trees.node_types import WAIT_FOR_COMPLETION, output_key
from aeroexec.trees.ports import MissingKey, request_from_ports, substitute
from aeroexec.trees.runtime.ticking import RUNNING, Node, kept
from py_trees.behaviour import Behaviour
from py_trees.common import Status

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

    def condition(self, text: str, blackboard: Any, where: str) -> Callable[[], bool]:
        """A pre-condition attribute as a function: a script (BT.CPP's meaning), or else, read with a warning, the
        belief expression aeroexec took there before (``<CheckBelief>`` or ``belief("...")`` is the portable way)."""
        from aeroexec.trees.script import ScriptError, compile_script

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
                self.record("tree_error", f"{where}: {error}", once=True)
                return False

        return holds

    def action(self, text: str, blackboard: Any, where: str) -> Callable[[], None]:
        """A post-condition attribute (``_onSuccess``...) as a function running its script."""
        from aeroexec.trees.script import ScriptError, compile_script

        script = compile_script(text)

        def run() -> None:
            try:
                script.run(blackboard, self.belief_holds)
            except (ScriptError, BeliefError) as error:
                self.record("tree_error", f"{where}: {error}", once=True)

        return run

    def stop_started(self, reason: str) -> None:
        """Stop every behavior this tree started that is still active (INTERRUPTED)."""
        coordinator = self.engine.coordinator
        for activation in reversed(self.started):
            if coordinator.active().get(activation.name) is activation:
                coordinator.stop(activation.name, reason)
        self.started.clear()


class Leaf(Node, Behaviour):
    """A leaf built from a model node: ``source`` is the node (file, line) and ``blackboard`` its scope."""

    def __init__(self, name: str, context: TreeContext, blackboard: Any, source: Any = None) -> None:
        super().__init__(name)
        self.context, self.blackboard, self.source = context, blackboard, source

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
        return Status.FAILURE


class BehaviorLeaf(Leaf):
    """A catalog behavior with its arguments as ports."""

    def __init__(self, name: str, behavior: str, ports: Mapping[str, str], context: TreeContext, blackboard: Any,
                 source: Any = None, skip_ports: tuple[str, ...] = ()) -> None:
        super().__init__(name, context, blackboard, source)
        self.behavior, self.ports, self.skip_ports = behavior, dict(ports), skip_ports
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


class AskBehaviorLeaf(BehaviorLeaf):
    """``<AskBehavior behavior="GENERATE_PATH_FREE_OF_OBSTACLES" DESTINATION="..." result="{path}"/>``."""

    def __init__(self, name: str, ports: Mapping[str, str], context: TreeContext, blackboard: Any,
                 source: Any = None) -> None:
        super().__init__(name, ports.get("behavior", "").strip(), ports, context, blackboard, source,
                         skip_ports=("behavior", "result"))
        self.key = output_key(ports.get("result", "result"))

    def finished(self, value: Any) -> Status:
        self.blackboard[self.key] = value
        return Status.SUCCESS


class BeliefLeaf(Leaf):
    """Condition, QueryBelief, AddBelief and RemoveBelief on the engine's belief memory."""

    def __init__(self, name: str, kind: str, belief: str, context: TreeContext, blackboard: Any,
                 source: Any = None) -> None:
        super().__init__(name, context, blackboard, source)
        self.kind, self.belief = kind, belief
        self.multivalued = False
        self.condition = kind in ("Condition", "CheckBelief")
        self.fixed = "{" not in belief  # no blackboard key to read: the text is the question

    def step(self) -> Status:
        if not (self.condition and self.fixed):
            return super().step()
        try:  # a condition without blackboard keys, ticked in one call (Leaf.step and update)
            status = Status.SUCCESS if self.context.engine.memory.holds(self.belief) else Status.FAILURE
        except BeliefError as error:
            status = self.error(f"{self.kind} {self.belief}: {error}")
        return kept(self, status)

    def update(self) -> Status:
        memory = self.context.engine.memory
        try:
            text = self.belief if self.fixed else substitute(self.belief, self.blackboard, as_term=True)
            if self.condition:
                return Status.SUCCESS if memory.holds(text) else Status.FAILURE
            if self.kind == "QueryBelief":
                found = memory.query(text)
                if found is None:
                    return Status.FAILURE
                for variable, value in found.items():
                    self.blackboard[str(variable).lstrip("?")] = to_python(value)
                return Status.SUCCESS
            if self.kind == "AddBelief":
                self.add(text)
            else:
                memory.remove(text)
            return Status.SUCCESS
        except (BeliefError, MissingKey) as error:
            return self.error(f"{self.kind} {self.belief}: {error}")

    def add(self, text: str) -> None:
        """Add a belief; a predicate the catalog does not declare is declared by the mission (``multivalued``)."""
        engine = self.context.engine
        belief = parse_belief(text)
        if belief.name not in engine.catalog.predicates:
            engine.memory.declare(belief.name, len(belief.args), multivalued=self.multivalued)
        engine.memory.add(belief)


class RuleLeaf(Leaf):
    """AddRule: the ``rule`` port's rules (and facts) added to the belief memory the first time it is ticked."""

    def __init__(self, name: str, rule: str, context: TreeContext, blackboard: Any, source: Any = None) -> None:
        super().__init__(name, context, blackboard, source)
        self.rule, self.added = rule, False

    def update(self) -> Status:
        if not self.added:
            try:
                self.context.engine.memory.add_rules(self.rule, getattr(self.source, "file", "") or self.name,
                                                     getattr(self.source, "line", 0) or 1)
            except BeliefError as error:
                return self.error(f"AddRule: {error}")
            self.added = True
        return Status.SUCCESS


class Constant(Leaf):
    """AlwaysSuccess / AlwaysFailure."""

    def __init__(self, name: str, status: Status, context: TreeContext, blackboard: Any, source: Any = None) -> None:
        super().__init__(name, context, blackboard, source)
        self.result = status

    def update(self) -> Status:
        return self.result

    def step(self) -> Status:
        return kept(self, self.result)
