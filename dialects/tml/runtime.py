"""Running a TML mission's event handlers: the node above the main task tree that lets events preempt it.

The semantics (the sources leave them open; aeroexec chooses these):

* **When events are checked.** At the start of every tick while the main tree waits for a behavior to complete
  (the Levant docs: handlers react "while the planner is waiting for a behavior to complete"); belief operations
  complete within their tick and are never interrupted. Events are not checked while a handler's tree runs:
  handlers do not nest. Several events true at once: the first in document order wins.
* **Edge-triggered.** An event fires when its condition holds and it has not fired since the condition was last
  seen false: it is armed at start and re-armed at a check where its condition is false, so a condition that stays
  true (the object still visible after REPEAT_TASK) does not fire again and again. The ``?X`` variables the
  condition binds become mission variables (``+X`` in the called tree).
* **Firing.** The main tree is halted: the running behavior of the interrupted leaf task ends INTERRUPTED, and the
  recurrent behaviors of that task and of the tasks around it are switched off. Then the tree named by ``call``
  runs (with its own recurrent behaviors); if it fails, the mission fails (its termination is not applied).
* **Termination**, once the called tree succeeds (or at once, without ``call``):
  REPEAT_TASK: the main tree resumes at the interrupted leaf task, which starts again (its recurrent behaviors and
  those of the tasks around it are switched on again); NEXT_TASK: the main tree resumes at the leaf task after the
  interrupted one (after the last one, the mission completes); END_MISSION: the mission completes (SUCCESS);
  ABORT_MISSION: the mission fails (FAILURE). Neither lands the drone: the handler's tree does that when it should
  (``aeroexec run`` lands a drone left in the air when the mission ends).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

from aeroexec.beliefs import BeliefError, to_python
from aeroexec.dialects.tml.reader import TmlEvent
from aeroexec.trees.ports import MissingKey, substitute
from aeroexec.trees.runtime.nodes.controls import Control, SequenceWithMemory
from aeroexec.trees.runtime.nodes.decorators import Decorator
from aeroexec.trees.runtime.nodes.parallels import Parallel
from aeroexec.trees.runtime.ticking import Result, halt
from py_trees.behaviour import Behaviour
from py_trees.common import Status

logger = logging.getLogger(__name__)


class TmlEventHandling(Control):
    """Children: the main tree first, then each tree an event calls; ``events`` in document order."""

    memory = ("armed", "handling", "interrupted", "main_done")  # kept by trees.runtime.tree_state

    def __init__(self, name: str, main: Behaviour, called: Mapping[str, Behaviour], events: list[TmlEvent],
                 context: Any, blackboard: Any, needs: Mapping[str, list[str]] | None = None) -> None:
        """``needs``: the variables each called tree uses before binding them itself."""
        super().__init__(name, [main, *called.values()])
        self.main = main
        self.called = dict(called)
        self.events = events
        self.context, self.blackboard = context, blackboard
        self.armed = [True] * len(events)
        self.handling: TmlEvent | None = None
        self.interrupted: list[Behaviour] = []  # the running path when the last event fired
        self.main_done = False
        self.needs = dict(needs or {})

    # -- the tick ----------------------------------------------------------------------------------
    def run(self) -> Result:
        if self.handling is None and self.main.status is Status.RUNNING:
            event = self.check_events()
            if event is not None:
                self.fire(event)
                missing = [v for v in self.needs.get(event.call or "", []) if v not in self.blackboard]
                if missing:  # verification warned it may happen: fail clearly rather than fly half the tree
                    self.handling = None
                    names = ", ".join(f"+{v}" for v in missing)
                    self.context.record("tml_handler_failed", f"{event.name}: {names} not bound: the event fired "
                                        f"before any <consult> bound {', '.join('?' + v for v in missing)}; the "
                                        f"tree {event.call} cannot run and the mission fails", event=event.name)
                    return Status.FAILURE
        if self.handling is not None:
            event = self.handling
            if event.call:
                tree = self.called[event.call]
                result = self.tick_index(list(self.called).index(event.call) + 1)
                if result is Status.RUNNING:
                    return Status.RUNNING
                if result is Status.FAILURE:
                    self.handling = None
                    self.context.record("tml_handler_failed", f"{event.name}: the tree {event.call} failed; "
                                                              f"the mission fails", event=event.name)
                    halt(tree)
                    return Status.FAILURE
            self.handling = None
            ended = self.terminate_with(event)
            if ended is not None:
                return ended
        if self.main_done:
            return Status.SUCCESS
        return self.tick_index(0)

    def check_events(self) -> TmlEvent | None:
        """The first armed event whose condition holds now (every condition is evaluated, to re-arm)."""
        chosen: TmlEvent | None = None
        for index, event in enumerate(self.events):
            found = self.query(event)
            if found is None:
                self.armed[index] = True
                continue
            if chosen is None and self.armed[index]:
                self.armed[index] = False
                chosen = event
                for variable, value in found.items():
                    name = str(variable).lstrip("?")
                    if name:
                        self.blackboard[name] = to_python(value)
        return chosen

    def query(self, event: TmlEvent) -> dict | None:
        try:
            return self.context.engine.memory.query(substitute(event.condition, self.blackboard, as_term=True))
        except (BeliefError, MissingKey) as error:
            self.context.record("tree_error", f"{self.context_where(event)}: {event.condition}: {error}", once=True)
            return None

    def context_where(self, event: TmlEvent) -> str:
        return f"event {event.name!r} (line {event.condition_line})"

    # -- preempting and resuming -------------------------------------------------------------------
    def fire(self, event: TmlEvent) -> None:
        path = running_path(self.main)
        leaf = path[-1] if path else self.main
        self.context.record("tml_event", f"{event.name}: {event.condition} holds; interrupting {leaf.name}"
                                         f"{f', calling {event.call}' if event.call else ''} ({event.mode})",
                            event=event.name, task=leaf.name, call=event.call or "", mode=event.mode)
        self.handling = event
        self.interrupted = path
        halt(self.main)
        if event.call:
            tree = self.called[event.call]
            if tree.status is not Status.INVALID:
                tree.stop(Status.INVALID)  # shown IDLE, started afresh

    def terminate_with(self, event: TmlEvent) -> Status | None:
        """Apply the event's termination mode; the mission's result, or None to resume the main tree."""
        mode = event.mode
        path = self.interrupted
        if mode == "END_MISSION":
            self.context.record("tml_termination", f"{event.name}: END_MISSION: the mission completes", mode=mode)
            return Status.SUCCESS
        if mode == "ABORT_MISSION":
            self.context.record("tml_termination", f"{event.name}: ABORT_MISSION: the mission fails", mode=mode)
            return Status.FAILURE
        if mode == "NEXT_TASK" and not skip_task(path):
            self.main_done = True
        what = "the interrupted task starts again" if mode == "REPEAT_TASK" else \
            "the mission goes on with the next task" if not self.main_done else "no task is left: the mission completes"
        self.context.record("tml_termination", f"{event.name}: {mode}: {what}", mode=mode)
        return None

    def halted(self) -> None:
        self.handling = None


def running_path(node: Behaviour) -> list[Behaviour]:
    """The nodes from ``node`` down to the running leaf task (through sequences' current child and task bodies)."""
    path: list[Behaviour] = []
    while node is not None and node.status is Status.RUNNING:
        path.append(node)
        if isinstance(node, SequenceWithMemory):
            node = node.children[node.index] if node.index < len(node.children) else None
        elif isinstance(node, Parallel):
            node = node.children[-1]  # the task's body (its recurrent behaviors come first)
        elif isinstance(node, Decorator):
            node = node.decorated
        else:
            break
    return path


def skip_task(path: list[Behaviour]) -> bool:
    """Move the halted main tree past the interrupted leaf task; False when it was the last one."""
    sequences = [n for n in path if isinstance(n, SequenceWithMemory)]
    for depth in range(len(sequences) - 1, -1, -1):
        sequence = sequences[depth]
        if sequence.index + 1 < len(sequence.children):
            sequence.index += 1
            for inner in sequences[depth + 1:]:
                inner.index = 0
            return True
    for sequence in sequences:
        sequence.index = 0
    return False
