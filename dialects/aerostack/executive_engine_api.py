"""Aerostack Levant's Python mission API (``import executive_engine_api as api``), served by aeroexec's engine.

The functions and return conventions of Levant's ``executive_engine_api`` (and of
its later version in python_based_mission_interpreter), over
:mod:`aeroexec.engine.api`: ``executeBehavior`` returns the termination cause
(``'GOAL_ACHIEVED'``...; ``'ERROR'`` when the activation was refused),
``activateBehavior`` returns ``(ack, uid)``, ``inhibitBehavior`` takes the uid or
the behavior's name, ``consultBelief``/``queryBelief`` return ``(success, dict)``
keyed by variable names without ``?``. Any predicate may be added, as in Aerostack.
"""

from __future__ import annotations

import logging
from typing import Any

from aeroexec.beliefs import BeliefError, UnknownPredicateError
from aeroexec.engine import api
from aeroexec.engine.events import Outcome

logger = logging.getLogger(__name__)

#: What a refused activation returns from executeBehavior / executeTask (Aerostack's value).
ERROR = "ERROR"


def termination(started: bool, outcome: Outcome) -> str:
    """The termination cause of a behavior run: its outcome, or ERROR when it never started."""
    return outcome if started or outcome is Outcome.GOAL_ACHIEVED else ERROR


def executeBehavior(behavior: str, **args: Any) -> str:
    """Execute a behavior and wait until it ends; its termination cause (GOAL_ACHIEVED, TIME_OUT, ...), or ERROR
    when the request is refused (Aerostack's convention: the refusal is in the event log and the run's summary
    says "completed with refused requests"; :mod:`aeroexec.engine.api` raises instead)."""
    try:
        return termination(*api.run_behavior(behavior, **args))
    except api.RequestRejected:
        return ERROR


def activateBehavior(behavior: str, **args: Any) -> tuple[bool, int]:
    """Activate a behavior and return at once: ``(ack, uid)``; ``(False, 0)`` when refused."""
    try:
        return api.start_behavior(behavior, **args)
    except api.RequestRejected:
        return False, 0


def inhibitBehavior(behavior: int | str) -> bool:
    """Stop an activation by its uid (from activateBehavior) or a behavior by name; False when not active."""
    if isinstance(behavior, int) and not isinstance(behavior, bool):
        return api.stop_activation(behavior)
    return api.stop_behavior(str(behavior))


def deactivateBehavior(behavior_uid: int | str, name: str | None = None) -> bool:
    """Stop the activation ``behavior_uid`` (a name is accepted too); False when it is not active."""
    if isinstance(behavior_uid, str):
        return api.stop_behavior(behavior_uid)
    return api.stop_activation(behavior_uid)


def isActiveBehavior(behavior: str) -> bool:
    return api.is_active_behavior(behavior)


def addBelief(belief: str, multivalued: bool = False) -> bool:
    """Add a belief (a new predicate is declared by adding it); False when it is not a well-formed belief."""
    try:
        api.add_belief(belief, multivalued=multivalued)
    except BeliefError as error:
        logger.error("addBelief(%r): %s", belief, error)
        return False
    return True


def removeBelief(belief: str) -> bool:
    """Remove the beliefs matching ``belief``; True when at least one was removed."""
    try:
        return api.remove_belief(belief) > 0
    except UnknownPredicateError:
        return False
    except BeliefError as error:
        logger.error("removeBelief(%r): %s", belief, error)
        return False


def queryBelief(expression: str) -> tuple[bool, dict[str, Any]]:
    """``(success, unification)`` of the first match, the unification keyed by variable name (``'X'`` for ``?X``)."""
    try:
        success, unification = api.consult_belief(expression)
    except UnknownPredicateError:  # a predicate nobody has added yet: no belief matches
        return False, {}
    return success, {str(key).lstrip("?"): value for key, value in unification.items()}


def trueBelief(expression: str) -> bool:
    """True when the belief expression matches the memory."""
    try:
        return api.true_belief(expression)
    except UnknownPredicateError:
        return False


def consultPlanner(planner: str, **args: Any) -> Any:
    """Ask a deliberative behavior (a planner such as GENERATE_PATH_FREE_OF_OBSTACLES) for its result."""
    return api.ask_behavior(planner, **args)


# Levant's and the later spellings of the same functions.
assertBelief = addBelief
retractBelief = removeBelief
consultBelief = queryBelief

__all__ = ["activateBehavior", "addBelief", "assertBelief", "consultBelief", "consultPlanner", "deactivateBehavior",
           "executeBehavior", "inhibitBehavior", "isActiveBehavior", "queryBelief", "removeBelief", "retractBelief",
           "trueBelief"]
