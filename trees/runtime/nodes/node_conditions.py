"""BehaviorTree.CPP's pre- and post-conditions of any node: ``_failureIf``, ``_successIf``, ``_skipIf``, ``_while``,
then ``_onSuccess``, ``_onFailure``, ``_onHalted`` and ``_post``, as a wrapper that takes the node's place in the tree.

BT.CPP checks them inside every node's tick; here a node that has some is wrapped in :class:`NodeConditions` (the
wrapped node is marked ``hidden``: the wrapper shows its status and carries its model node).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from aeroexec.trees.runtime.nodes.decorators import Decorator
from aeroexec.trees.runtime.ticking import FAILURE, RUNNING, SKIPPED, SUCCESS, Result, TickError, halt
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class NodeConditions(Decorator):
    """``conditions`` maps each pre-condition attribute to a function telling whether its script holds; the first
    three and a false ``_while`` are checked when the node starts (FAILURE, SUCCESS, SKIPPED without ticking it); a
    ``_while`` that becomes false while the node runs halts it and the node is SKIPPED. ``actions`` maps each
    post-condition attribute to a function running its script."""

    ORDER = ("_failureIf", "_successIf", "_skipIf", "_while")

    def __init__(self, name: str, child: Behaviour, conditions: dict[str, Callable[[], bool]],
                 actions: dict[str, Callable[[], None]] | None = None, context: Any = None) -> None:
        super().__init__(name, child)
        self.conditions = conditions
        self.actions = actions or {}
        self.context = context

    def run(self) -> Result:
        result = self.checked()
        if result is SUCCESS or result is FAILURE:  # BT.CPP's post-conditions: _onSuccess/_onFailure, _post
            action = self.actions.get("_onSuccess" if result is SUCCESS else "_onFailure")
            if action is not None:
                action()
            if "_post" in self.actions:
                self.actions["_post"]()
        return result

    def halted(self) -> None:
        if "_onHalted" in self.actions and self.status is RUNNING:
            try:
                self.actions["_onHalted"]()
            except TickError as error:  # a halt goes on: the error is recorded
                if self.context is not None:
                    self.context.record("tree_error", str(error), node=self.name)

    def checked(self) -> Result:
        starting = self.status is not RUNNING
        for attribute in self.ORDER:
            check = self.conditions.get(attribute)
            if check is None:
                continue
            holds = check()
            if starting and holds and attribute != "_while":
                self.feedback_message = f"{attribute} holds"
                return {"_failureIf": Status.FAILURE, "_successIf": Status.SUCCESS}.get(attribute, SKIPPED)
            if attribute == "_while" and not holds:
                self.feedback_message = "_while does not hold"
                halt(self.decorated)
                return SKIPPED
        decorated = self.decorated
        return decorated.stepper(decorated)
