"""The engine's belief leaves: CheckBelief (and its old spelling ``<Condition belief>``), QueryBelief, AddBelief and
RemoveBelief on the engine's belief memory.

Belief expressions may read the blackboard with ``{key}``; QueryBelief writes each variable it unifies (``?P`` ->
key ``P``). An expression that cannot be read makes the node FAILURE, with a ``tree_error`` naming its place.
"""

from __future__ import annotations

import abc

from aeroexec.beliefs import BeliefError, parse_belief, to_python
from aeroexec.trees.ports import MissingKey, substitute
from aeroexec.trees.runtime.actions import Leaf
from aeroexec.trees.runtime.ports import BOOL, STRING, InputPort, NodeConfig, Port
from aeroexec.trees.runtime.ticking import kept
from py_trees.common import Status


def _belief(meaning: str) -> Port:
    return InputPort("belief", STRING, required=True, description=meaning)


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
    """SUCCESS when the belief expression holds, else FAILURE."""

    ports = (_belief("a belief expression; SUCCESS when it holds"),)

    def step(self) -> Status:
        if not self.fixed:
            return super().step()
        try:  # a condition without blackboard keys, ticked in one call (Leaf.step and update)
            status = Status.SUCCESS if self.context.engine.memory.holds(self.belief) else Status.FAILURE
        except BeliefError as error:
            status = self.error(f"{type(self).__name__} {self.belief}: {error}")
        return kept(self, status)

    def apply(self, text: str) -> Status:
        return Status.SUCCESS if self.context.engine.memory.holds(text) else Status.FAILURE


class Condition(CheckBelief):
    """``<Condition belief="..."/>``, aeroexec's old spelling of CheckBelief (BT.CPP refuses it)."""


class QueryBelief(BeliefLeaf):
    """Writes each variable the expression binds (``?P`` -> key ``P``); FAILURE when it has no answer."""

    ports = (_belief("a belief expression; its variables go to the blackboard"),)

    def apply(self, text: str) -> Status:
        found = self.context.engine.memory.query(text)
        if found is None:
            return Status.FAILURE
        for variable, value in found.items():
            self.blackboard[str(variable).lstrip("?")] = to_python(value)
        return Status.SUCCESS


class AddBelief(BeliefLeaf):
    """Adds a belief; a predicate the catalog does not declare is declared by the mission (``multivalued``)."""

    ports = (_belief("a ground belief to add"),
             InputPort("multivalued", BOOL, "false", "a predicate the catalog does not declare may hold several "
                                                     "values at once (default false)"))

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

    ports = (_belief("a belief pattern; matching beliefs are removed"),)

    def apply(self, text: str) -> Status:
        self.context.engine.memory.remove(text)
        return Status.SUCCESS
