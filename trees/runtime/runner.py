"""Running a behavior-tree mission on the engine: the tree is ticked by the engine's own loop, once per period.

``TreeMission(document, engine).run(max_time)`` builds the tree, ticks it at the end of every engine tick (the
engine's ``tick_callbacks``) until its root completes, and records events the terminal can show:
``mission_started``, ``node_status`` for every change of a node's status (``node``, ``old``, ``new``, ``line``,
``depth``, ``uid``: the node's 1-based place in ``nodes``, as in the Groot2 log), then ``mission_completed``
(root SUCCESS) or ``mission_failed`` (root FAILURE, halted, time limit, or a node that cannot tick: a script error,
a port it cannot read, recorded first as a ``tree_error`` naming the node and its line). ``observers`` are called
after each tick with ``(node, status it returned)`` for every node it ticked (children before their parent, as
py_trees' ``tick()`` yields them), and with None when the tree is halted. The tree is ticked one call per node
(``trees.runtime.ticking``): the nodes record their status changes as they happen, and only those are reported.
Halting a tree halts every running node and stops every behavior the tree started (INTERRUPTED). When a change
while it runs (``trees.runtime.changes``) gives the tree other nodes, :meth:`TreeMission.restructure` rebuilds its
node list and places, and ``restructured`` listeners (the .btlog writer, Groot2) hear of it before the next tick.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from typing import Any

from aeroexec.trees.model import TreeDocument
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.builder import build_tree, describe, model_of
from aeroexec.trees.runtime.context import TreeContext
from aeroexec.trees.runtime.ticking import TickError, TickState, attach, result_name, status_name, step
from py_trees.behaviour import Behaviour
from py_trees.common import Status

logger = logging.getLogger(__name__)


class TreeMission:
    """One run of a tree document on an engine (build it after verification; see ``trees.verify``)."""

    def __init__(self, document: TreeDocument, engine: Any, name: str | None = None,
                 blackboard: Mapping[str, Any] | None = None) -> None:
        self.document, self.engine = document, engine
        self.name = name or document.main
        self.context = TreeContext(engine)
        self.blackboard = Blackboard(values=blackboard)
        self.root: Behaviour = build_tree(document, self.context, self.blackboard)
        self.nodes = describe(self.root)
        self._places = {id(node): (uid, depth, node) for uid, (depth, node) in enumerate(self.nodes, 1)}
        self._statuses: dict[int, str] = {}
        self._state = attach(self.root, TickState())
        self.status: Status = Status.INVALID
        self.started = False
        self.done = False
        self.paused = False  # by the operator (engine.supervisor): the tree is not ticked
        self._launched = False  # its first tick done (the waits nothing gave at launch said then)
        self.observers: list[Callable[[list[tuple[Behaviour, str]] | None], None]] = []  # e.g. the .btlog writer
        self.restructured: list[Callable[[], None]] = []  # told when a change gave the tree other nodes

    # -- on the engine loop --------------------------------------------------------------------
    def start(self) -> None:
        """Tick the tree from the next engine tick on."""
        if self.started:
            return
        self.started = True
        self.engine.log.record("mission_started", detail=self.name, tree=self.document.main)
        self.engine.tick_callbacks.append(self.tick)
        if getattr(self.engine, "supervisor", None) is not None:
            self.engine.supervisor.attach(self)

    def tick(self) -> None:
        """One tick of the tree (the engine calls it each period); finishes the mission when the root completes."""
        if self.done or self.paused:
            return
        state = self._state
        state.visits = [] if self.observers else None
        try:
            step(self.root, state)
        except TickError as error:  # BT.CPP throws out of the tick: the mission fails, naming the node
            self.engine.log.record("tree_error", detail=str(error), node=getattr(error.node, "name", ""),
                                   line=getattr(error.node, "line", 0))
            self._report(scan=True)
            self.halt(f"{error.what} failed at {error.where or 'its node'}: {error.message}")
            return
        except Exception as exc:  # a bug in a node: the mission stops, the engine goes on
            logger.exception("the behavior tree %s failed", self.name)
            self._report(scan=True)
            self.halt(f"{type(exc).__name__}: {exc}")
            return
        self.status = self.root.status
        self._report(scan=state.foreign)
        if not self._launched:
            self._launched = True
            self._say_waits()
        if state.visits is not None:
            self._notify([(node, result_name(result)) for node, result in state.visits])
        if self.status in (Status.SUCCESS, Status.FAILURE):
            self._finish("mission_completed" if self.status == Status.SUCCESS else "mission_failed",
                         f"{self.name}: the tree ended {status_name(self.root)}")

    def halt(self, reason: str = "halted", kind: str = "mission_failed") -> None:
        """Halt every running node and stop every behavior the tree started; the mission ends with an event of
        ``kind`` (``mission_replaced`` when a new mission is loaded in its place)."""
        if self.done:
            return
        waits = self.waiting_for()
        if self.root.status != Status.INVALID:
            self.root.stop(Status.INVALID)
        self._report(scan=self._state.foreign)
        self._notify(None)
        waited = (f"; it was waiting for {', '.join(f'the belief {b} ({where})' for b, where in waits)}, which "
                  f"nothing added (aeroexec ctl add gives it; aeroexec run --event or --alert at launch)"
                  if waits else "")
        self._finish(kind, f"{self.name}: halted ({reason}){waited}")

    def _say_waits(self) -> None:
        """After the first tick: a ``waiting`` event for each wait the tree is in that nothing gave at launch
        (Aerostack2's ``WaitForEvent start`` before anything flies), saying how to give it, so a tree does not wait
        silently until the time limit."""
        for belief, where in self.waiting_for():
            topic = _event_topic(belief)
            how = (f"give it at launch with --{topic[0]} {topic[1]}=VALUE, or while it runs with aeroexec ctl add "
                   f"\"{topic[0]}('{topic[1]}', VALUE)\"" if topic else
                   f"give it while it runs with aeroexec ctl add \"{belief}\"")
            self.engine.log.record("waiting", detail=f"{self.name} waits for {belief} ({where}), which nothing has "
                                                     f"given: {how}", belief=belief, where=where)

    def waiting_for(self) -> list[tuple[str, str]]:
        """The beliefs the tree waits for now, each with its place (``file:line``): a running wait until a belief
        holds (``KeepRunningUntilFailure`` over an ``Inverter`` of a CheckBelief or QueryBelief, as Aerostack2's
        WaitForEvent is mapped)."""
        waits = []
        for node in self.root.iterate():
            model = getattr(node, "source", None)
            if node.status is not Status.RUNNING or model is None or model.type != "KeepRunningUntilFailure":
                continue
            inverter = node.children[0] if node.children else None
            leaf = inverter.children[0] if inverter is not None and inverter.children else None
            leaf_model = getattr(leaf, "source", None)
            if (getattr(inverter, "source", None) is not None and inverter.source.type == "Inverter"
                    and leaf_model is not None and leaf_model.type in ("CheckBelief", "QueryBelief")):
                waits.append((leaf_model.ports.get("belief", ""), f"{model.file}:{model.line}"))
        return waits

    def pause(self) -> None:
        """Stop ticking the tree (the operator's pause); its running behaviors are the supervisor's business."""
        self.paused = True

    def resume(self) -> None:
        self.paused = False

    # -- changes while it runs (trees.runtime.changes) --------------------------------------------------------
    @property
    def tick_state(self) -> TickState:
        """What the tree's nodes share while it is ticked (new nodes are attached to it)."""
        return self._state

    def report(self) -> None:
        """Record the status changes not reported yet (``node_status`` events), now."""
        self._report(scan=self._state.foreign)

    def restructure(self) -> None:
        """The tree has other nodes (a change): its node list and places again, then the listeners."""
        self.nodes = describe(self.root)
        self._places = {id(node): (uid, depth, node) for uid, (depth, node) in enumerate(self.nodes, 1)}
        self._statuses = {key: status for key, status in self._statuses.items() if key in self._places}
        for listener in list(self.restructured):
            try:
                listener()
            except Exception:  # a log that cannot follow never stops the mission
                logger.exception("a listener of the behavior tree %s failed after a change", self.name)

    def _finish(self, kind: str, detail: str) -> None:
        self.done = True
        if self.tick in self.engine.tick_callbacks:
            self.engine.tick_callbacks.remove(self.tick)
        if getattr(self.engine, "supervisor", None) is not None:
            self.engine.supervisor.detach(self)
        self.context.stop_started(f"the behavior tree {self.name} ended")
        self.engine.log.record(kind, detail=detail, tree=self.document.main)

    def _notify(self, visited: list[tuple[Behaviour, str]] | None) -> None:
        for observer in list(self.observers):
            try:
                observer(visited)
            except Exception:  # an observer's bug (a log that cannot be written) never stops the mission
                logger.exception("an observer of the behavior tree %s failed", self.name)

    def _report(self, scan: bool = False) -> None:
        """A ``node_status`` event for each visible node whose status changed since the last report, in document
        order: the nodes that recorded a change (``scan``: every node, when a foreign behaviour may not record)."""
        changed = self._state.changed
        if not changed and not scan:
            return
        places = self._places
        if scan:
            chosen = [(uid, depth, node) for uid, (depth, node) in enumerate(self.nodes, 1)]
        else:
            chosen = sorted({places[id(node)] for node in changed if id(node) in places}, key=lambda p: p[0])
        changed.clear()
        for uid, depth, node in chosen:  # uid: the node's place in document order
            new = status_name(node)
            old = self._statuses.get(id(node), "IDLE")
            if new == old:
                continue
            self._statuses[id(node)] = new
            model = model_of(node)
            self.engine.log.record("node_status", detail=f"{node.name}: {old} -> {new}", node=node.name,
                                   old=old, new=new, type=getattr(model, "type", ""),
                                   line=getattr(model, "line", 0), depth=depth, uid=uid)

    # -- from the caller's thread --------------------------------------------------------------
    def run(self, max_time: float | None = None) -> Status:
        """Run the engine loop until the tree completes (or ``max_time`` engine seconds pass: then it is halted)."""
        self.start()
        self.engine.run_until(lambda: self.done, max_time if max_time is not None else float("inf"))
        if not self.done:
            self.halt("time limit" if not self.engine.stopped else "engine stopped")
        return self.status

    def display(self) -> str:
        """The tree as text, one node a line with its status (``[RUNNING] GO_TO_POINT``)."""
        return "\n".join(f"{'  ' * depth}[{status_name(node)}] {node.name}" for depth, node in self.nodes)


def _event_topic(belief: str) -> tuple[str, str] | None:
    """``("event", "start")`` for the belief ``event('start', ?)`` a WaitForEvent waits for (``alert`` likewise),
    else None."""
    import re

    found = re.fullmatch(r"\s*(event|alert)\(\s*'((?:[^'\\]|\\.)*)'\s*,.*\)\s*", belief)
    return (found.group(1), found.group(2)) if found else None
