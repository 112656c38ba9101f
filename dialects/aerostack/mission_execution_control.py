"""Aerostack Sirocco's Python mission API (``import mission_execution_control as mxc``), served by aeroexec.

The functions and return conventions of Sirocco's ``mission_execution_control``
over :mod:`aeroexec.engine.api`: ``executeTask`` returns ``(finished, result)``
(``(False, 'ERROR')`` when the task was refused), ``startTask`` and ``stopTask``
a bool, ``queryBelief`` ``(success, dict)`` keyed by variable names without ``?``.
"""

from __future__ import annotations

from typing import Any

from aeroexec.dialects.aerostack.executive_engine_api import (
    ERROR,
    addBelief,
    consultPlanner,
    queryBelief,
    removeBelief,
    termination,
    trueBelief,
)
from aeroexec.engine import api
from aeroexec.engine.events import Outcome


def startTask(task: str, **args: Any) -> bool:
    """Start a task (a behavior) and return at once: True when it was accepted."""
    try:
        ack, _ = api.start_behavior(task, **args)
    except api.RequestRejected:  # Aerostack's convention: refused is False, not an exception
        return False
    return ack


def executeTask(task: str, **args: Any) -> tuple[bool, str]:
    """Execute a task and wait until it ends: ``(True, termination cause)``, or ``(False, 'ERROR')`` if refused; a
    task that ended without its goal (TIME_OUT, WRONG_PROGRESS) fails the run, whatever the mission does next."""
    try:
        started, outcome = api.run_behavior(task, **args)
    except api.RequestRejected:  # Aerostack's convention: refused is (False, 'ERROR'), not an exception
        return False, ERROR
    if started and outcome in (Outcome.TIME_OUT, Outcome.WRONG_PROGRESS):
        api.task_failed(task, outcome)  # the mission may ignore the result: the run does not
    return started or outcome is Outcome.GOAL_ACHIEVED, termination(started, outcome)


def stopTask(task: str) -> bool:
    """Stop a task by name; False when it was not active."""
    return api.stop_behavior(task)


__all__ = ["ERROR", "addBelief", "consultPlanner", "executeTask", "queryBelief", "removeBelief", "startTask",
           "stopTask", "trueBelief"]
