"""The engine's belief leaves: CheckBelief (and its old spelling ``<Condition belief>``), QueryBelief, AddBelief,
RemoveBelief and AddRule on the engine's belief memory.

Belief expressions may read the blackboard with ``{key}``; QueryBelief writes each variable it unifies (``?P`` ->
key ``P``). An expression that cannot be read makes the node FAILURE, with a ``tree_error`` naming its place.
"""

from __future__ import annotations

import abc
from typing import Any

from aeroexec.beliefs import BeliefError, parse_belief, to_python
from aeroexec.trees.ports import MissingKey, substitute
from aeroexec.trees.runtime.manifests import MANIFESTS
from aeroexec.trees.runtime.nodes.actions import Leaf
from aeroexec.trees.runtime.ports import NodeConfig
from aeroexec.trees.runtime.ticking import FAILURE, SUCCESS
from py_trees.common import Status


class BeliefLeaf(Leaf):
    """A leaf with a belief expression (``{key}`` read from the blackboard when it is ticked)."""

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.belief = config.model.ports.get("belief", "")
        self.fixed = "{" not in self.belief  # no blackboard key to read: the text is the question

    def update(self) -> Status:
        try:
            text = self.belief if self.fixed else substitute(self.belief, self.blackboard, as_term=True)
            return self.apply(text)
        except (BeliefError, MissingKey) as error:
            return self.error(f"{type(self).__name__} {self.belief}: {error}")

    @abc.abstractmethod
    def apply(self, text: str) -> Status:
        """What the leaf does with its expression, ``{key}`` read."""


class CheckBelief(BeliefLeaf):
    """SUCCESS when the belief expression holds, else FAILURE.

    A condition without blackboard keys keeps its last answer with the memory's ``version`` it stands at
    (``BeliefMemory.holds_standing``): ticked again while the memory has not changed, it answers at once, without
    asking (a question reading computed predicates, shared beliefs or beliefs that expire is asked every time).
    """

    __slots__ = ("answer", "ask", "belief", "belief_memory", "fixed", "quick", "seen")  # read at every tick: in slots
    manifest = MANIFESTS["CheckBelief"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        memory = getattr(getattr(config.context, "engine", None), "memory", None)  # the engine keeps it for a run
        self.belief_memory = memory
        self.ask = memory.holds_standing if memory is not None else None
        self.quick = self.fixed and memory is not None  # ticked in one call, asking the engine's memory
        self.answer, self.seen = FAILURE, -1  # the last answer, and the memory's version it stands at (-1: none)

    def step(self) -> Status:
        if not self.quick:
            return super().step()
        if self.belief_memory.version == self.seen:  # the memory is as it was when it answered: the same answer
            status = self.answer
        else:
            try:  # Leaf.step, update and kept in one call
                held, self.seen = self.ask(self.belief)
                status = self.answer = SUCCESS if held else FAILURE
            except BeliefError as error:
                self.seen = -1
                status = self.error(f"{type(self).__name__} {self.belief}: {error}")
        tree = self.tree
        if status is not self.status:
            tree.changed.append(self)
            self.status = status
        self.ticked = tree.number
        if tree.visits is not None:
            tree.visits.append((self, status))
        return status

    def apply(self, text: str) -> Status:
        return Status.SUCCESS if self.context.engine.memory.holds(text) else Status.FAILURE


class Condition(CheckBelief):
    """``<Condition belief="..."/>``, aeroexec's old spelling of CheckBelief (BT.CPP refuses it)."""

    manifest = MANIFESTS["Condition"]


class QueryBelief(BeliefLeaf):
    """Writes each variable the expression binds (``?P`` -> key ``P``); FAILURE when it has no answer."""

    manifest = MANIFESTS["QueryBelief"]

    def apply(self, text: str) -> Status:
        found = self.context.engine.memory.query(text)
        if found is None:
            return Status.FAILURE
        for variable, value in found.items():
            self.blackboard[str(variable).lstrip("?")] = to_python(value)
        return Status.SUCCESS


class AddBelief(BeliefLeaf):
    """Adds a belief; a predicate the catalog does not declare is declared by the mission (``multivalued``)."""

    manifest = MANIFESTS["AddBelief"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.multivalued = config.model.ports.get("multivalued", "false").strip().lower() in ("true", "1", "yes")

    def apply(self, text: str) -> Status:
        engine = self.context.engine
        belief = parse_belief(text)
        if belief.name not in engine.catalog.predicates:
            engine.memory.declare(belief.name, len(belief.args), multivalued=self.multivalued)
        engine.memory.add(belief)
        return Status.SUCCESS


class RemoveBelief(BeliefLeaf):
    """Removes the beliefs matching the pattern."""

    manifest = MANIFESTS["RemoveBelief"]

    def apply(self, text: str) -> Status:
        self.context.engine.memory.remove(text)
        return Status.SUCCESS


class AddRule(Leaf):
    """Adds the rules (and facts) of its ``rule`` port the first time it is ticked; FAILURE when they cannot be
    taken (each problem named with the node's file and line)."""

    manifest = MANIFESTS["AddRule"]

    def __init__(self, name: str, config: NodeConfig) -> None:
        super().__init__(name, config)
        self.rule, self.added = config.model.ports.get("rule", ""), False
        self.file, self.line = config.model.file, config.model.line or 1

    def update(self) -> Status:
        if not self.added:
            try:
                self.context.engine.memory.add_rules(self.rule, self.file or self.name, self.line)
            except BeliefError as error:
                return self.error(f"AddRule: {error}")
            self.added = True
        return Status.SUCCESS

    def resumed(self, engine: Any) -> None:
        """A resumed run: the rules it added before live in the memory, so they are added again."""
        if self.added:
            engine.memory.add_rules(self.rule, self.file or self.name, self.line)
