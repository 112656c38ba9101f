"""The ports of the built-in nodes, declared and read as BehaviorTree.CPP declares and reads them.

A node class declares its ports once, in ``ports`` (BT.CPP's ``providedPorts()``): ``InputPort("num_cycles",
"int")``. The builder hands each node a :class:`NodeConfig` (BT.CPP's ``NodeConfig``: the model node with its
ports as written, the blackboard of its scope, the tree's context); the node asks it for an :class:`Input` per
port it reads. Verification (``trees.verify``) reads the same declarations: the ports a node has, those it
needs, the values they take.

A port's text is its value, converted once to the port's type (:func:`convert`); a port written ``{key}`` is
read from the blackboard each time the node reads it. A value that cannot be read raises :class:`PortError`
(BT.CPP throws out of the tick: the run fails, naming the node).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from aeroexec.trees.model import TreeNode
from aeroexec.trees.ports import bare_key, parse_number
from py_trees.common import Status

#: Port types (BT.CPP's C++ types): how text becomes a value of each.
INT, UNSIGNED, DOUBLE, BOOL, STRING, STATUS, ANY = "int", "unsigned", "double", "bool", "string", "NodeStatus", "any"
#: NodeStatus as text, with BT.CPP's fourth status.
SKIPPED = "SKIPPED"
STATUSES = {"SUCCESS": Status.SUCCESS, "FAILURE": Status.FAILURE, "RUNNING": Status.RUNNING, "SKIPPED": SKIPPED,
            "IDLE": Status.INVALID}


class PortError(ValueError):
    """A port whose value cannot be read (a key nothing wrote, text that is not of the port's type)."""


@dataclass(frozen=True, slots=True)
class Port:
    """One port of a node type (BT.CPP's ``PortInfo``): its name, type, direction, default text and whether the
    XML must write it (BT.CPP then fails at the first read of a port left out without a default)."""

    name: str
    type: str = STRING
    direction: str = "input"  # input, output, inout
    default: str | None = None
    required: bool = False
    description: str = ""

    @property
    def reads(self) -> bool:
        return self.direction != "output"

    @property
    def writes(self) -> bool:
        return self.direction != "input"


def InputPort(name: str, type: str = STRING, default: str | None = None, description: str = "",  # noqa: N802
              required: bool = False) -> Port:
    """BT.CPP's ``InputPort<T>(name, default, description)``."""
    return Port(name, type, "input", default, required, description)


def OutputPort(name: str, type: str = ANY, description: str = "", required: bool = False) -> Port:  # noqa: N802
    """BT.CPP's ``OutputPort<T>(name, description)``: the ``{key}`` (or plain key) the node writes."""
    return Port(name, type, "output", None, required, description)


def BidirectionalPort(name: str, type: str = ANY, description: str = "",  # noqa: N802
                      required: bool = False) -> Port:
    """BT.CPP's ``BidirectionalPort<T>(name, description)``."""
    return Port(name, type, "inout", None, required, description)


def _integer(text: str) -> int:
    value = parse_number(text)
    if not isinstance(value, int):
        raise PortError(f"Can't convert string [{text}] to integer")
    return value


def _unsigned(text: str) -> int:
    value = _integer(text)
    if value < 0:
        raise PortError(f"Value out of bound when converting [{text}] to integer")
    return value


def _double(text: str) -> float:
    value = parse_number(text)
    if value is None:
        raise PortError(f"Can't convert string [{text}] to double")
    return float(value)


def _bool(text: str) -> bool:
    if text in ("1", "true", "TRUE", "True"):
        return True
    if text in ("0", "false", "FALSE", "False"):
        return False
    raise PortError(f"Can't convert string [{text}] to bool")


def _status(text: str) -> Status | str:
    if text.strip() not in STATUSES:
        raise PortError(f"Cannot convert this to NodeStatus: {text}")
    return STATUSES[text.strip()]


#: BT.CPP's ``convertFromString<T>``, per port type.
CONVERSIONS: dict[str, Callable[[str], Any]] = {INT: _integer, UNSIGNED: _unsigned, DOUBLE: _double, BOOL: _bool,
                                                STATUS: _status, STRING: str, ANY: str}


def queue_items(text: str, item: str) -> list[Any]:
    """BT.CPP's ``convertFromString<SharedQueue<T>>``: the items between ``;``, each converted (none in "")."""
    parts = text.split(";")
    if parts and not parts[-1]:
        parts.pop()  # "1;2;" has two items, as in BT.CPP's splitString
    return [convert(part, item) for part in parts]


def convert(text: str, kind: str) -> Any:
    """A port's text as a value of type ``kind`` (raises :class:`PortError`); ``queue<T>``: a list of T."""
    if kind.startswith("queue<"):
        return queue_items(text, kind[6:-1])
    return CONVERSIONS[kind](text if kind in (STRING, ANY) else text.strip())


def from_blackboard(value: Any, kind: str) -> Any:
    """A blackboard value read by a port of type ``kind``: text is converted, numbers cast, others kept."""
    if isinstance(value, str):
        return convert(value, kind)
    if kind in (INT, UNSIGNED) and isinstance(value, int | float) and not isinstance(value, bool):
        if value != int(value) or (kind == UNSIGNED and value < 0):
            raise PortError(f"{value!r} is no {'unsigned ' if kind == UNSIGNED else ''}integer")
        return int(value)
    if kind == DOUBLE and isinstance(value, int | float):
        return float(value)
    if kind == BOOL and isinstance(value, int | float):
        return bool(value)
    if kind == STRING:
        return str(value)
    return value


class Input:
    """One input port of one node: its text converted once, or its ``{key}`` read and converted by :meth:`get`."""

    __slots__ = ("board", "key", "kind", "node", "port", "value")

    def __init__(self, node: TreeNode, port: Port, text: str | None, board: Any) -> None:
        self.node, self.port, self.kind, self.board = node, port, port.type, board
        self.key = bare_key(text) if text is not None else None
        self.value: Any = None
        if text is not None and self.key is None:
            try:
                self.value = convert(text, port.type)
            except PortError as error:
                raise PortError(f"{node.where}: the port {port.name} of {node.type}: {error}") from None

    @property
    def given(self) -> bool:
        """Whether the port has a value (written, or a default) or reads a key."""
        return self.key is not None or self.value is not None

    def get(self) -> Any:
        """The port's value now (raises :class:`PortError` when the key it reads holds none, or a wrong one)."""
        key = self.key
        if key is None:
            return self.value
        board = self.board
        if key not in board:
            raise PortError(f"{self.node.where}: {self.node.type} cannot read its port {self.port.name}: the "
                            f"blackboard has no value for {{{key}}}")
        try:
            return from_blackboard(board[key], self.kind)
        except PortError as error:
            raise PortError(f"{self.node.where}: {self.node.type} cannot read its port {self.port.name} from "
                            f"{{{key}}}: {error}") from None


@dataclass(slots=True)
class NodeConfig:
    """What a node is built with (BT.CPP's ``NodeConfig``): its model node (type, name, ports as written, file and
    line), the blackboard of its scope and the tree's context (``runtime.context.TreeContext``)."""

    model: TreeNode
    blackboard: Any
    context: Any = None

    @classmethod
    def of(cls, kind: str, ports: dict[str, str] | None = None, blackboard: Any = None,
           context: Any = None) -> NodeConfig:
        """A node of type ``kind`` with these ports as written, outside any file (an embedding, a test)."""
        return cls(TreeNode(kind, kind, dict(ports or {})), blackboard if blackboard is not None else {}, context)

    def input(self, name: str, ports: tuple[Port, ...]) -> Input:
        """The reader of the input port ``name`` of ``ports`` (the node's declarations): its text, else its
        default."""
        port = next((p for p in ports if p.name == name), None)
        if port is None:
            raise KeyError(f"{self.model.type} declares no port {name}")
        text = self.model.ports.get(name)
        if text is None or (not text.strip() and port.default is not None):
            text = port.default
        return Input(self.model, port, text, self.blackboard)

    def output(self, name: str) -> str:
        """The blackboard key an output port writes (``{key}`` or a plain key)."""
        text = self.model.ports.get(name, "")
        return bare_key(text) or text.strip()
