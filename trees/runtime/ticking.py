"""How the runtime's nodes tick: one plain call per node, with statuses and their changes kept as they happen.

py_trees ticks a tree through a chain of generators (``tick()`` yields every node it ticks) and formats a debug
string at every tick and stop; BehaviorTree.CPP ticks with one call per node. The runtime's nodes stay py_trees
behaviours (``tick()``, ``stop()``, ``iterate()``, visitors and display work) but a tree is ticked with
:func:`tick_tree`, which calls each node's ``step()``: it ticks the node once and returns its result (a
:class:`Status`, or :data:`SKIPPED`). The nodes of one tree share a :class:`TickState`: the nodes whose status
changed (the runner reports those, not a scan of the tree), the nodes ticked with their results (only while
someone observes them: the .btlog, Groot2), and the children to show IDLE again once the tick is over. That last
one is BehaviorTree.CPP's look without its cost: a control node starting again used to reset every child at once;
now the children it ticks again are not touched, and those it did not reach are reset when the tick ends.

A foreign py_trees behaviour in the tree (a leaf type registered by an embedding robot) is ticked through its own
``tick()``; the runner then falls back to a full status scan.
"""

from __future__ import annotations

from collections.abc import Iterator
from types import MethodType
from typing import Any

from aeroexec.trees import conversions
from aeroexec.trees.runtime.manifests import ACTION, NodeManifest
from py_trees import logging as py_trees_logging
from py_trees.behaviour import Behaviour
from py_trees.common import Status

#: The fourth status of BehaviorTree.CPP; a node ends SUCCESS and ``skipped`` is set.
SKIPPED = conversions.SKIPPED
Result = Status | str
RUNNING, SUCCESS, FAILURE, INVALID = Status.RUNNING, Status.SUCCESS, Status.FAILURE, Status.INVALID


class TickError(RuntimeError):
    """A node that cannot go on ticking: a script that fails (a variable nothing wrote, a type mismatch), a port it
    cannot read. BT.CPP throws out of the tick; the run fails naming the node (``where``: file:line), unless a
    TryCatch around it catches it."""

    def __init__(self, node: Any, message: str) -> None:
        self.node, self.message = node, message
        kind, name = getattr(node, "type", ""), getattr(node, "name", "")
        self.what = kind if name in ("", kind) else f"{kind} {name!r}"
        super().__init__(f"{self.where}: {self.what}: {message}" if self.where else f"{self.what}: {message}")

    @property
    def where(self) -> str:
        return getattr(self.node, "where", "")


_MAKING = object()  # Node.__init__: the node is being made


class _Discard(list):
    """A list that keeps nothing: what a node outside any ticked tree records."""

    def append(self, item: Any) -> None:
        pass


class TickState:
    """What the nodes of one tree share while it is ticked (see the module's docstring)."""

    __slots__ = ("changed", "foreign", "number", "stale", "visits")

    def __init__(self) -> None:
        self.number = 0  # the current tick
        self.changed: list[Behaviour] = []  # nodes whose status (or skipped) changed, in the order they changed
        self.visits: list[tuple[Behaviour, Result]] | None = None  # nodes ticked with their results, when observed
        self.stale: list[tuple[Behaviour, int]] = []  # (control node started again, first child to show IDLE)
        self.foreign = False  # the tree holds a behaviour that is not a runtime node


_DETACHED = TickState()
_DETACHED.changed = _Discard()
_DETACHED.stale = _Discard()


class Node:
    """Mixed into every runtime node: ``step()``, and py_trees' ``tick()`` and ``stop()`` built on it."""

    # what a tick reads of every node, in slots (fixed places in the object, not its dictionary): a tree of
    # thousands of nodes is read from far less memory
    __slots__ = ("children", "current_child", "decorated", "skipped", "source", "status", "stepper", "ticked", "tree")

    #: whether the class has an ``initialise`` of its own (py_trees' does nothing: it is not called then)
    initialises = False
    #: what the node type is to the XML (``runtime.manifests``): its ports (BehaviorTree.CPP's ``providedPorts()``),
    #: children and whether it loops; a built-in node's is its name's in ``MANIFESTS``
    manifest = NodeManifest(ACTION)

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.initialises = getattr(cls, "initialise", Behaviour.initialise) is not Behaviour.initialise

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.tree = _DETACHED
        # its class's ``step`` function: a parent ticks a child with ``child.stepper(child)``, read from the child's
        # slot, where ``child.step()`` would look the method up in the child's class and dictionary and bind it
        self.stepper = type(self).step
        self.skipped = False
        self.ticked = -1  # the tick number it was last ticked in
        self.__dict__["_logger"] = _MAKING
        super().__init__(*args, **kwargs)
        if self.__dict__.get("_logger") is _MAKING:
            del self.__dict__["_logger"]

    # py_trees gives every behaviour a logger and a tick generator of its own as it makes it; a tree of thousands of
    # nodes uses neither, and they spread its nodes over far more memory: both are made when first asked for
    @property
    def logger(self) -> py_trees_logging.Logger:
        made = self.__dict__.get("_logger")
        if made is None or made is _MAKING:
            made = self.__dict__["_logger"] = py_trees_logging.Logger(self.name)
        return made

    @logger.setter
    def logger(self, value: py_trees_logging.Logger) -> None:
        if self.__dict__.get("_logger") is not _MAKING:  # the one py_trees makes in __init__ is dropped
            self.__dict__["_logger"] = value

    @property
    def iterator(self) -> Iterator[Behaviour]:
        return self.tick()

    @iterator.setter
    def iterator(self, value: Any) -> None:
        value.close()  # py_trees' generator: ``tick()`` makes one when asked

    def step(self) -> Result:
        """Tick the node once and return its result (the status it is left with; SKIPPED)."""
        raise NotImplementedError

    def tick(self) -> Iterator[Behaviour]:
        """py_trees' tick: the tree under this node ticked once; yields each node ticked, as py_trees does."""
        if self.tree is _DETACHED:
            attach(self, TickState())  # type: ignore[arg-type]
        for node, _ in tick_tree(self):  # type: ignore[arg-type]
            yield node

    def stop(self, new_status: Status = INVALID) -> None:
        """py_trees' stop without its debug string: a halt (INVALID) stops the children first, then ``terminate``;
        the change is recorded for the runner."""
        if new_status is INVALID:
            for child in self.children:
                if child.status is not INVALID:
                    child.stop(INVALID)
            if hasattr(self, "current_child"):
                self.current_child = None
        self.terminate(new_status)  # type: ignore[attr-defined]
        if self.status is not new_status or self.skipped:
            self.tree.changed.append(self)  # type: ignore[arg-type]
        self.status = new_status
        self.skipped = False

    def settle(self, old: Status, old_skipped: bool, result: Result) -> Result:
        """Keep the result of a tick: the status (SKIPPED is SUCCESS + ``skipped``), the change, the visit."""
        tree = self.tree
        if result is SKIPPED:
            status, skipped = SUCCESS, True
        else:
            status, skipped = result, False
        if status is not old or skipped is not old_skipped:
            tree.changed.append(self)  # type: ignore[arg-type]
        self.status = status  # type: ignore[assignment]
        self.skipped = skipped
        self.ticked = tree.number
        if tree.visits is not None:
            tree.visits.append((self, result))  # type: ignore[arg-type]
        return result


def kept(node: Node, status: Status) -> Status:
    """A leaf's new status kept: its change recorded, its visit too when observed (``Leaf.step``)."""
    tree = node.tree
    if status is not node.status:
        tree.changed.append(node)  # type: ignore[arg-type]
        node.status = status
    node.ticked = tree.number
    if tree.visits is not None:
        tree.visits.append((node, status))  # type: ignore[arg-type]
    return status


def _foreign_step(node: Behaviour) -> Result:
    """``step()`` of a py_trees behaviour that is not a runtime node: ticked through its own generator."""
    tree: TickState = node.tree  # type: ignore[attr-defined]
    old = node.status
    for ticked in node.tick():
        if tree.visits is not None:
            tree.visits.append((ticked, result_of(ticked)))
    if node.status is not old:
        tree.changed.append(node)
    node.ticked = tree.number  # type: ignore[attr-defined]
    return result_of(node)


def attach(root: Behaviour, state: TickState) -> TickState:
    """Make ``state`` the tick state of every node under ``root`` (a foreign behaviour gets a ``step()``)."""
    for node in root.iterate():
        node.tree = state  # type: ignore[attr-defined]
        if not isinstance(node, Node):
            state.foreign = True
            node.ticked = -1  # type: ignore[attr-defined]
            node.step = MethodType(_foreign_step, node)  # type: ignore[attr-defined]
            node.stepper = _foreign_step  # type: ignore[attr-defined]
    return state


def tick_tree(root: Behaviour) -> list[tuple[Behaviour, Result]]:
    """Tick an attached tree once from ``root``; the nodes ticked with the results they returned, in the order
    they returned them (children before their parent, as py_trees yields them)."""
    state: TickState = root.tree  # type: ignore[attr-defined]
    observed = state.visits
    visits: list[tuple[Behaviour, Result]] = []
    state.visits = visits
    try:
        step(root, state)
    finally:
        state.visits = observed
    if observed is not None:
        observed.extend(visits)
    return visits


def step(root: Behaviour, state: TickState) -> None:
    """Tick an attached tree once from ``root`` (the runner's fast path: ``state.visits`` as the caller set it)."""
    state.number += 1
    try:
        root.stepper(root)  # type: ignore[attr-defined]
    finally:
        stale = state.stale
        if stale:
            number = state.number
            for node, start in stale:
                children = node.children
                for index in range(start, len(children)):
                    child = children[index]
                    if child.ticked != number and child.status is not INVALID:
                        child.stop(INVALID)
            stale.clear()


def result_of(node: Behaviour) -> Result:
    """A node's status, SKIPPED when it was skipped."""
    return SKIPPED if node.status is SUCCESS and getattr(node, "skipped", False) else node.status


def status_name(node: Behaviour) -> str:
    """The status as BehaviorTree.CPP names it: IDLE, RUNNING, SUCCESS, FAILURE or SKIPPED."""
    result = result_of(node)
    return "IDLE" if result is INVALID else result if isinstance(result, str) else result.value


def result_name(result: Result) -> str:
    """A result as BehaviorTree.CPP names it."""
    return "IDLE" if result is INVALID else result if isinstance(result, str) else result.value


def halt(node: Behaviour) -> None:
    """BehaviorTree.CPP's ``haltChild`` of a running node: it is stopped, and the behaviors it runs.

    A completed node keeps its status (shown until it starts again): ticking it again starts it afresh anyway.
    """
    if node.status is RUNNING:
        node.stop(INVALID)


def reset(node: Behaviour) -> None:
    """Back to IDLE (a running node is halted first)."""
    if node.status is not INVALID:
        node.stop(INVALID)
