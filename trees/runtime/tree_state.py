"""A running tree's state, captured as data and put back into a tree built from the same document: every node's
status and its memory (a sequence's index, a Repeat's count, a RetryUntilSuccessful's attempts, a RunOnce's first
result, a Loop's queue, a Parallel's completed children, a Timeout's start...) and every blackboard scope.

The flight journal keeps the last state of a tree mission so that a resumed run goes on from where the tree was
(``aeroexec run --resume``); live mission changes are made on the same records. The API:

- :func:`walk` yields ``(path, node)`` for every node, the wrappers of pre- and post-conditions included; a path
  is the child indexes from the root joined by dots (``""`` the root, ``"0.2"`` its first child's third child).
  :func:`node_at` finds a node by path.
- :func:`capture` gives a :class:`TreeState` (:class:`Capture` captures a tree again and again): a
  :class:`NodeState` per node (path, type, name, status, memory) and the blackboard scopes' entries;
  :meth:`TreeState.to_json` / :meth:`TreeState.from_json` keep it as text.
- :func:`restore` puts a state back into a freshly built tree (raising :class:`TreeStateError`, naming the first
  node that differs, when the tree is not the one captured). A node that was RUNNING is RUNNING again, its memory
  as it was: ticked next, it goes on (a running behavior leaf starts its behavior again); completed nodes keep
  their status, so a sequence's index skips them. :func:`restore_mission` does it for a
  :class:`~aeroexec.trees.runtime.runner.TreeMission` (its reported statuses too, so nothing is reported twice).

What a node remembers is its kind's ``memory`` (``trees.runtime.kinds``; :data:`MEMORY`: class name -> attributes,
looked up along the class's bases); a node class of another package may say it with a ``memory`` class attribute.
Values are kept by :mod:`aeroexec.engine.missions.values` (a tuple stays a tuple); a status as its name; a node as
its path.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from aeroexec.engine.missions.values import decode, encode
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.kinds import memory_by_class
from aeroexec.trees.runtime.ticking import SKIPPED, status_name
from py_trees.behaviour import Behaviour
from py_trees.common import Status

#: What each node class remembers between ticks besides its status (class name -> attributes): each node kind's
#: ``memory`` (``trees.runtime.kinds``), by the name of the class that runs it.
MEMORY: dict[str, tuple[str, ...]] = memory_by_class()
_PLAIN = frozenset({int, float, bool, type(None)})
_STATUS = {"IDLE": Status.INVALID, "RUNNING": Status.RUNNING, "SUCCESS": Status.SUCCESS,
           "FAILURE": Status.FAILURE, "SKIPPED": Status.SUCCESS}
FORMAT = 1


class TreeStateError(ValueError):
    """A state that does not fit the tree it is put back into."""


@dataclass
class NodeState:
    """One node: where it is (``path``), what it is (``type``: its class, ``name``), its status and memory."""

    path: str
    type: str
    name: str
    status: str  # IDLE, RUNNING, SUCCESS, FAILURE or SKIPPED
    memory: dict[str, Any] = field(default_factory=dict)  # attribute -> value as kept (see the module)


@dataclass
class TreeState:
    """A tree's nodes in walk order and its blackboard scopes (the mission's first, then each SubTree's as first
    met): ``{"values": {key: value}, "versions": {key: writes}}`` with values as kept."""

    nodes: list[NodeState]
    blackboards: list[dict[str, Any]] = field(default_factory=list)

    def node(self, path: str) -> NodeState | None:
        return next((n for n in self.nodes if n.path == path), None)

    def running(self) -> list[NodeState]:
        """The nodes that were RUNNING, in walk order (a running leaf last on its branch)."""
        return [n for n in self.nodes if n.status == "RUNNING"]

    def shape(self) -> list[list[str]]:
        """``[path, type, name]`` of every node: what the state must be put back into."""
        return [[n.path, n.type, n.name] for n in self.nodes]

    def to_json(self, shape: bool = True) -> str:
        """The state as text; without ``shape``, only each node's status and memory, in walk order (a journal keeps
        the tree's shape once and its states many times)."""
        nodes = [[n.status, n.memory] if n.memory else n.status for n in self.nodes]
        data: dict[str, Any] = {"format": FORMAT, "nodes": nodes, "blackboards": self.blackboards}
        if shape:
            data["shape"] = self.shape()
        return json.dumps(data, separators=(",", ":"))

    @classmethod
    def from_json(cls, text: str, shape: list[list[str]] | None = None) -> TreeState:
        """The state :meth:`to_json` wrote (``shape``: the tree's, when it was written without)."""
        data = json.loads(text)
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise TreeStateError("not a tree state this version of aeroexec can read")
        shape = data.get("shape", shape)
        if not isinstance(shape, list) or len(shape) != len(data["nodes"]):
            raise TreeStateError("a tree state without the shape of its tree")
        nodes = [NodeState(path, kind, name, *(node if isinstance(node, list) else (node, {})))
                 for (path, kind, name), node in zip(shape, data["nodes"], strict=True)]
        return cls(nodes, list(data.get("blackboards", [])))


# -- finding nodes -----------------------------------------------------------------------------------------
def walk(root: Behaviour) -> Iterator[tuple[str, Behaviour]]:
    """Every node under ``root`` (``root`` first) with its path, depth first in document order."""
    stack: list[tuple[str, Behaviour]] = [("", root)]
    while stack:
        path, node = stack.pop()
        yield path, node
        prefix = f"{path}." if path else ""
        stack.extend((f"{prefix}{i}", child) for i, child in reversed(list(enumerate(node.children))))


def node_at(root: Behaviour, path: str) -> Behaviour:
    """The node at ``path``; KeyError when there is none."""
    node = root
    for part in filter(None, path.split(".")):
        index = int(part)
        if not 0 <= index < len(node.children):
            raise KeyError(path)
        node = node.children[index]
    return node


def memory_of(node: Behaviour) -> tuple[str, ...]:
    """The attributes ``node`` remembers between ticks (:data:`MEMORY`, or its class's ``memory``)."""
    cls = type(node)
    found = _MEMORY_OF.get(cls)
    if found is None:
        own = getattr(cls, "memory", None)
        found = tuple(own) if own is not None else next(
            (MEMORY[c.__name__] for c in cls.__mro__ if c.__name__ in MEMORY), ())
        _MEMORY_OF[cls] = found
    return found


_MEMORY_OF: dict[type, tuple[str, ...]] = {}


def scopes(root: Behaviour, blackboard: Blackboard | None = None) -> list[Blackboard]:
    """The blackboard scopes of a tree: ``blackboard`` (the mission's) first, then each node's as first met."""
    found: list[Blackboard] = [blackboard] if isinstance(blackboard, Blackboard) else []
    seen = {id(b) for b in found}
    for _, node in walk(root):
        for board in (getattr(getattr(node, "config", None), "blackboard", None), getattr(node, "blackboard", None)):
            if isinstance(board, Blackboard) and id(board) not in seen:
                seen.add(id(board))
                found.append(board)
    return found


# -- capture and restore -------------------------------------------------------------------------------------
def capture(root: Behaviour, blackboard: Blackboard | None = None) -> TreeState:
    """The state of the tree under ``root`` now (``blackboard``: the mission's scope, first of the scopes)."""
    return Capture(root, blackboard)()


class Capture:
    """Captures the tree under ``root`` again and again (the flight journal keeps a mission's state after every tick
    that changed it): its walk, its scopes and each node's memory are looked up once, so make a new one when the
    tree changes shape (``TreeMission.restructured``)."""

    def __init__(self, root: Behaviour, blackboard: Blackboard | None = None) -> None:
        walked = list(walk(root))
        self.paths = {id(node): path for path, node in walked}
        self.nodes = [(path, node, type(node).__name__, memory_of(node)) for path, node in walked]
        self.boards = scopes(root, blackboard)

    def __call__(self) -> TreeState:
        """The tree's state now."""
        paths = self.paths
        nodes = []
        for path, node, kind, remembered in self.nodes:
            memory = {name: _out(getattr(node, name), node, paths) for name in remembered if hasattr(node, name)}
            current = getattr(node, "current_child", None)
            if current is not None and node.children:
                memory["current_child"] = next((i for i, c in enumerate(node.children) if c is current), None)
            nodes.append(NodeState(path, kind, node.name, status_name(node), memory))
        boards = [{"values": {k: encode(v) for k, v in board._local.items()}, "versions": dict(board._versions)}
                  for board in self.boards]
        return TreeState(nodes, boards)


def restore(root: Behaviour, state: TreeState, blackboard: Blackboard | None = None) -> None:
    """Put ``state`` back into the tree under ``root``, built afresh from the document it was captured from."""
    difference = first_difference(root, state)
    if difference is not None:
        raise TreeStateError(difference)
    nodes = dict(walk(root))
    for saved in state.nodes:
        node = nodes[saved.path]
        for name, value in saved.memory.items():
            if name == "current_child":
                node.current_child = node.children[value] if value is not None else None
            else:
                setattr(node, name, _in(value, nodes, node))
        node.status = _STATUS.get(saved.status, Status.INVALID)
        if hasattr(node, "skipped"):
            node.skipped = saved.status == "SKIPPED"
        if hasattr(node, "ticked"):
            node.ticked = -1
    boards = scopes(root, blackboard)
    if len(boards) != len(state.blackboards):
        raise TreeStateError(f"the tree has {len(boards)} blackboard scopes, the state {len(state.blackboards)}")
    for board, saved in zip(boards, state.blackboards, strict=True):
        board._local.clear()
        board._local.update({k: decode(v) for k, v in saved.get("values", {}).items()})
        board._versions.clear()
        board._versions.update({k: int(v) for k, v in saved.get("versions", {}).items()})


def restore_mission(mission: Any, state: TreeState) -> None:
    """:func:`restore` into a :class:`~aeroexec.trees.runtime.runner.TreeMission` that has not started: its nodes,
    blackboard, status, and the statuses it last reported (a node is reported again only when it changes)."""
    restore(mission.root, state, mission.blackboard)
    mission.status = mission.root.status
    mission._statuses.update({id(node): status_name(node) for _, node in mission.nodes
                              if status_name(node) != "IDLE"})
    mission._state.changed.clear()


def shape(root: Behaviour) -> list[tuple[str, str, str]]:
    """``(path, type, name)`` of every node: what must agree for a state to fit a tree."""
    return [(path, type(node).__name__, node.name) for path, node in walk(root)]


def first_difference(root: Behaviour, state: TreeState) -> str | None:
    """Where ``state`` does not fit the tree under ``root`` (the first node that differs, in words), or None."""
    built = shape(root)
    for (path, kind, name), saved in zip(built, state.nodes, strict=False):
        if (path, kind, name) != (saved.path, saved.type, saved.name):
            where = getattr(getattr(_node(root, path), "source", None), "where", "") or f"node {path or 'root'}"
            return (f"{where}: the tree has {kind} {name!r} where the interrupted run had {saved.type} "
                    f"{saved.name!r}")
    if len(built) != len(state.nodes):
        more = "more" if len(built) > len(state.nodes) else "fewer"
        return f"the tree has {more} nodes ({len(built)}) than the interrupted run's ({len(state.nodes)})"
    return None


def _node(root: Behaviour, path: str) -> Behaviour | None:
    try:
        return node_at(root, path)
    except KeyError:
        return None


def _out(value: Any, owner: Behaviour, paths: dict[int, str]) -> Any:
    if type(value) in _PLAIN:
        return value
    if isinstance(value, Status) or value is SKIPPED:
        return {"status": "SKIPPED" if value is SKIPPED else value.value}
    if isinstance(value, Behaviour):
        return {"node": paths.get(id(value), "")}
    if isinstance(value, list) and any(isinstance(v, Behaviour) for v in value):
        return [_out(v, owner, paths) for v in value]
    events = getattr(owner, "events", None)  # a TML event handler's event: its place in the handler's list
    if isinstance(events, list) and value is not None and any(value is e for e in events):
        return {"event": next(i for i, e in enumerate(events) if e is value)}
    return encode(value)


def _in(data: Any, nodes: dict[str, Behaviour], owner: Behaviour) -> Any:
    if isinstance(data, dict) and len(data) == 1:
        (tag, inner), = data.items()
        if tag == "status":
            return SKIPPED if inner == "SKIPPED" else Status(inner)
        if tag == "node":
            return nodes[inner]
        if tag == "event":
            return owner.events[inner]  # type: ignore[attr-defined]
    if isinstance(data, list) and any(isinstance(v, dict) and "node" in v for v in data):
        return [_in(v, nodes, owner) for v in data]
    return decode(data)


__all__ = ["MEMORY", "Capture", "NodeState", "TreeState", "TreeStateError", "capture", "first_difference", "memory_of",
           "node_at", "restore", "restore_mission", "scopes", "shape", "walk"]
