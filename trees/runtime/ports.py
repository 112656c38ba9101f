"""The ports of the built-in nodes, read as BehaviorTree.CPP reads them.

A node type declares its ports once, in its manifest (``runtime.manifests``, BT.CPP's ``providedPorts()``):
``InputPort("num_cycles", "int")``. The builder hands each node a :class:`NodeConfig` (BT.CPP's ``NodeConfig``: the
model node with its ports as written, the blackboard of its scope, the tree's context); the node asks it for an
:class:`Input` per port it reads. Verification (``trees.verify``) reads the same declarations: the ports a node
has, those it needs, the values they take.

A port's text is its value, converted once to the port's type (:func:`convert`); a port written ``{key}`` is
read from the blackboard each time the node reads it. A value that cannot be read raises :class:`PortError`
(BT.CPP throws out of the tick: the run fails, naming the node).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from aeroexec.trees.conversions import ConversionError, convert, from_blackboard, text_of
from aeroexec.trees.model import TreeNode
from aeroexec.trees.ports import bare_key
from aeroexec.trees.runtime.manifests import Port
from aeroexec.trees.runtime.ticking import TickError


class PortError(ValueError):
    """A port whose value cannot be read (a key nothing wrote, text that is not of the port's type)."""


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
            except ConversionError as error:
                raise PortError(f"{node.where}: the port {port.name} of {node.type}: the value \"{text}\" can not "
                                f"be converted to {port.type} ({error})") from None

    @property
    def given(self) -> bool:
        """Whether the port has a value (written, or a default) or reads a key."""
        return self.key is not None or self.value is not None

    def get(self) -> Any:
        """The port's value now; raises :class:`TickError` when the key it reads holds none, or a wrong one."""
        key = self.key
        if key is None:
            if self.value is None:
                raise TickError(self.node, f"the port {self.port.name} has no value")
            return self.value
        board = self.board
        if key not in board:
            raise TickError(self.node, f"cannot read the port {self.port.name}: the blackboard has no value for "
                                       f"{{{key}}}")
        try:
            return from_blackboard(board[key], self.kind)
        except ConversionError as error:
            raise TickError(self.node, f"cannot read the port {self.port.name} from {{{key}}} "
                                       f"({text_of(board[key])!r}): {error}") from None


@dataclass(slots=True)
class NodeConfig:
    """What a node is built with (BT.CPP's ``NodeConfig``): its model node (type, name, ports as written, file and
    line), the blackboard of its scope and the tree's context (``runtime.context.TreeContext``).

    A port written ``{key}`` with a type of its own gives the blackboard's entry that type, as BT.CPP does when it
    loads a tree: text written there later (SetBlackboard, a script) is converted to it.
    """

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
        default (only when the port is not written at all, as in BT.CPP)."""
        port = self._declared(name, ports)
        text = self.model.ports.get(name, port.default)
        return Input(self.model, port, text, self.blackboard)

    def output(self, name: str, ports: tuple[Port, ...] = ()) -> str:
        """The blackboard key an output port writes (``{key}`` or a plain key)."""
        if ports:
            self._declared(name, ports)
        text = self.model.ports.get(name, "")
        return bare_key(text) or text.strip()

    def _declared(self, name: str, ports: tuple[Port, ...]) -> Port:
        port = next((p for p in ports if p.name == name), None)
        if port is None:
            raise KeyError(f"{self.model.type} declares no port {name}")
        key = bare_key(self.model.ports.get(name) or "")
        declare = getattr(self.blackboard, "declare", None)
        if key is not None and declare is not None:
            try:
                declare(key, port.type)
            except PortError as error:
                raise PortError(f"{self.model.where}: {error}") from None
        return port
