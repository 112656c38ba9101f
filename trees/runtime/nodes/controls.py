"""BehaviorTree.CPP v4's control nodes: :class:`Control`, the base of every one, and the sequences and fallbacks,
one class per node name, as ``py_trees`` composites with BT.CPP's semantics (parallels: ``parallels``; IfThenElse,
WhileDoElse, SwitchN and TryCatch: ``branches``).

| node | child FAILURE | child RUNNING |
|---|---|---|
| Sequence | restart from the first child | tick the same child again |
| ReactiveSequence | restart | restart: every child ticked again, the others halted |
| SequenceWithMemory | tick the failed child again | tick the same child again |

Fallback mirrors Sequence (memory while RUNNING, restart after SUCCESS or when every child failed);
ReactiveFallback ticks from the first child on every tick. The Async variants hand control back to the tree after
each child that completed on its first tick.

py_trees has no SKIPPED status: a skipped node ends SUCCESS with ``skipped`` set, and these composites treat it
as BehaviorTree.CPP does (passed over; all children skipped -> the composite is skipped too). Halting is
``stop(INVALID)``; a node halted while RUNNING stops the behavior it started.
"""

from __future__ import annotations

import abc
from typing import Any

import py_trees
from aeroexec.trees.runtime.manifests import MANIFESTS, control
from aeroexec.trees.runtime.ports import NodeConfig
from aeroexec.trees.runtime.ticking import (
    FAILURE,
    INVALID,
    RUNNING,
    SKIPPED,
    SUCCESS,
    Node,
    Result,
    reset,
)
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class Control(Node, py_trees.composites.Composite):
    """A composite whose ``run()`` decides its result from its children, BehaviorTree.CPP style."""

    manifest = control()  # one child or more; each node's is its name's
    #: whether it ticks its children in order from ``restart_from()`` (then reaching the last one means every one
    #: was ticked: none is left to show IDLE)
    in_order = False
    terminates = False
    fused = False  # Sequence.step: run() inlined

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, list(children or []))
        self.skipped = False
        self.config = config if config is not None else NodeConfig.of(type(self).__name__)

    @classmethod
    def build(cls, config: NodeConfig, children: list[Behaviour]) -> Behaviour:
        return cls(config.model.name, children, config)

    @abc.abstractmethod
    def run(self) -> Result:
        """One tick of this control node: its result (every control node says how it ticks)."""

    def step(self) -> Result:
        old, old_skipped = self.status, self.skipped
        tree = self.tree
        started = old is not RUNNING
        if started:
            start = self.restart_from()
            if self.initialises:
                self.initialise()
        result = self.run()
        if started and not (self.in_order and self.children and tree.number == self.children[-1].ticked):
            # started again: the children it did not tick again are shown IDLE once the tick ends (those it
            # ticked show their new status); a node ticking its children in order that reached its last one
            # ticked them all
            tree.stale.append((self, start))
        if result is RUNNING:
            status, skipped = result, False
        else:
            status, skipped = (SUCCESS, True) if result is SKIPPED else (result, False)
            if self.terminates:
                self.terminate(status)
        if status is not old or skipped is not old_skipped:  # Node.settle, inlined: every tick goes through here
            tree.changed.append(self)
        self.status, self.skipped, self.ticked = status, skipped, tree.number
        if tree.visits is not None:
            tree.visits.append((self, result))
        return result

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.terminates = cls.terminate is not Control.terminate  # Control's does nothing when a node completes
        cls.fused = not getattr(cls, "asynchronous", True) and not cls.initialises

    def restart_from(self) -> int:
        """The first child reset when the node starts again (the rest keep their status for display)."""
        return 0

    def reset_children(self, start: int = 0) -> None:
        """Halt the running children from ``start`` on."""
        children = self.children
        for index in range(start, len(children)):
            if children[index].status is RUNNING:
                children[index].stop(INVALID)

    def tick_index(self, index: int) -> Result:
        child = self.current_child = self.children[index]
        return child.stepper(child)  # type: ignore[attr-defined]

    def terminate(self, new_status: Status) -> None:
        if new_status is INVALID:
            self.halted()

    def halted(self) -> None:
        """Reset what a halt resets."""


# -- sequences and fallbacks ---------------------------------------------------------------------------------
class Sequence(Control):
    """A RUNNING child is ticked again; a failure restarts from the first child.

    ``stop_on`` is the result that ends the node early (FAILURE; SUCCESS for a Fallback); ``restart_on_stop``
    False keeps the index there (SequenceWithMemory); ``asynchronous``: a child that completed on its first tick
    hands control back to the tree (RUNNING) before the next child is ticked.
    """

    manifest = MANIFESTS["Sequence"]
    stop_on = FAILURE
    restart_on_stop = True
    asynchronous = False
    in_order = True
    # what the fused step reads at every tick, in slots: a tree of thousands of nodes is read from less memory
    __slots__ = ("index", "skipped_count", "_stop_on", "_fused", "_terminates", "_completed")

    def __init__(self, name: str, children: list[Behaviour] | None = None, config: NodeConfig | None = None) -> None:
        super().__init__(name, children, config)
        self.index = 0
        self.skipped_count = 0
        self._stop_on, self._fused, self._terminates = self.stop_on, self.fused, self.terminates
        self._completed = SUCCESS if self.stop_on is FAILURE else FAILURE  # when every child was ticked

    def run(self) -> Result:
        children = self.children
        count = len(children)
        if self.status is not RUNNING:
            self.skipped_count = 0
        index, stop_on, asynchronous = self.index, self.stop_on, self.asynchronous
        while index < count:
            child = children[index]
            before = child.status if asynchronous else None
            result = child.stepper(child)
            if result is RUNNING:
                self.index, self.current_child = index, child
                return RUNNING
            if result is stop_on:
                self.index, self.current_child = index, child
                if self.restart_on_stop:
                    self.reset_children()
                    self.index = 0
                else:
                    self.reset_children(index + 1)
                return stop_on
            index += 1
            if result is SKIPPED:
                self.skipped_count += 1
            elif asynchronous and before is not RUNNING and index < count:
                self.index, self.current_child = index, child
                return RUNNING
        self.current_child = children[-1] if children else None
        all_skipped = self.skipped_count == count
        self.index = self.skipped_count = 0
        return SKIPPED if all_skipped else SUCCESS if stop_on is FAILURE else FAILURE

    def step(self) -> Result:
        """Control.step and run() in one call for the sequences and fallbacks that are not asynchronous: they are
        most of a tree's control nodes. Their children are walked by a plain ``for`` loop (an index is only looked
        for where a child stops the node), and a node that ends as it was is left with its tick number written."""
        if not self._fused:
            return Control.step(self)
        tree, children = self.tree, self.children
        old, start, stop_on = self.status, self.index, self._stop_on  # start: where it starts again (restart_from)
        skipped = self.skipped_count if old is RUNNING else 0
        for child in children[start:] if start else children:
            result = child.stepper(child)
            if result is RUNNING or result is stop_on:
                index = children.index(child, start)
                self.index, self.current_child, self.skipped_count = index, child, skipped
                if result is stop_on:
                    if self.restart_on_stop:
                        self.reset_children()
                        self.index = 0
                    else:
                        self.reset_children(index + 1)
                if old is not RUNNING and children[-1].ticked != tree.number:
                    # started again: the children it did not tick are shown IDLE once the tick ends
                    tree.stale.append((self, start))
                break
            if result is SKIPPED:
                skipped += 1
        else:  # every child from ``start`` on ticked: none is left to show IDLE
            if not children:
                self.current_child = None
                result = SKIPPED
            else:
                self.current_child = children[-1]
                if start or skipped:
                    self.index = self.skipped_count = 0
                result = SKIPPED if skipped == len(children) else self._completed
            if result is old and not self.skipped:  # as it was: nothing changed (the common tick)
                if self._terminates:
                    self.terminate(result)
                self.ticked = tree.number
                if tree.visits is not None:
                    tree.visits.append((self, result))
                return result
        if result is SKIPPED:
            status, skipped_now = SUCCESS, True
        else:
            status, skipped_now = result, False
            if result is not RUNNING and self._terminates:
                self.terminate(status)
        if status is not old or skipped_now is not self.skipped:
            tree.changed.append(self)
        self.status, self.skipped, self.ticked = status, skipped_now, tree.number
        if tree.visits is not None:
            tree.visits.append((self, result))
        return result

    def halted(self) -> None:
        if self.restart_on_stop:
            self.index = 0
        self.skipped_count = 0


class AsyncSequence(Sequence):
    """A Sequence that hands control back to the tree after each child that completed on its first tick."""

    manifest = MANIFESTS["AsyncSequence"]
    asynchronous = True


class SequenceWithMemory(Sequence):
    """After a failure or a halt it resumes at the child that failed."""

    manifest = MANIFESTS["SequenceWithMemory"]
    restart_on_stop = False
    asynchronous = True

    def restart_from(self) -> int:
        return self.index  # the children before it are not ticked again


class Fallback(Sequence):
    """The first child that succeeds; a RUNNING child is ticked again."""

    manifest = MANIFESTS["Fallback"]
    stop_on = SUCCESS


class AsyncFallback(Fallback):
    manifest = MANIFESTS["AsyncFallback"]
    asynchronous = True


class ReactiveSequence(Control):
    """Every tick starts at the first child; a RUNNING child halts every other child (completed ones back to IDLE);
    the first FAILURE ends it (a ReactiveFallback: the first SUCCESS)."""

    manifest = MANIFESTS["ReactiveSequence"]
    stop_on, otherwise = FAILURE, SUCCESS
    in_order = True

    def run(self) -> Result:
        all_skipped = True
        for index, child in enumerate(self.children):
            result = self.tick_index(index)
            all_skipped &= result is SKIPPED
            if result is RUNNING:
                for other in self.children:
                    if other is not child:
                        reset(other)
                return RUNNING
            if result == self.stop_on:
                self.reset_children()
                return self.stop_on
        return SKIPPED if all_skipped else self.otherwise


class ReactiveFallback(ReactiveSequence):
    manifest = MANIFESTS["ReactiveFallback"]
    stop_on, otherwise = SUCCESS, FAILURE
