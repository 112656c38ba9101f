"""The blackboard of a tree run: a mapping of keys to values, scoped per SubTree with BehaviorTree.CPP's remapping.

A SubTree has a blackboard of its own. ``<SubTree ID="X" goal="{target}"/>`` maps the subtree's ``goal`` to the
parent's ``target`` (reads and writes go through); ``speed="1.5"`` sets a literal in the subtree (a number
when the text is one, as BT.CPP 4.10 does);
``_autoremap="true"`` shares every other key with the parent under the same name, except a ``_private`` one
(underscore-prefixed), which stays the subtree's own (BT.CPP's ``IsPrivateKey``).

An entry may have a type, given by the port of a built-in node that reads or writes it (``declare``), as BT.CPP
types an entry when it loads a tree: text written to it is converted to that type (``"3"`` to the integer 3 for a
``num_cycles``), and two ports of different types on one entry are refused.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping, MutableMapping
from typing import Any

from aeroexec.trees.conversions import ANY, compatible, from_blackboard, type_conflict
from aeroexec.trees.model import COMMON_ATTRIBUTES
from aeroexec.trees.ports import bare_key
from aeroexec.trees.runtime.ports import PortError

_INTEGER = re.compile(r"-?[0-9]+")
_REAL = re.compile(r"-?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf(?:inity)?|nan)", re.IGNORECASE)


def subtree_literal(text: str) -> int | float | str:
    """A SubTree's literal port value as BT.CPP 4.10 stores it in the subtree's blackboard: an integer when the whole
    text is one (``std::from_chars``, no ``.``/``e``), else a double when the whole text is one, else the text
    (4.10's ``LiteralNumericPortsPreserveType``; 4.8 kept the text)."""
    if "." not in text and "e" not in text and "E" not in text and _INTEGER.fullmatch(text):
        number = int(text)
        if -2 ** 63 <= number < 2 ** 63:
            return number
    if _REAL.fullmatch(text):
        return float(text)
    return text


class Blackboard(MutableMapping[str, Any]):
    """Keys and values of one tree scope; ``remap`` sends a key to the parent under another name."""

    def __init__(self, parent: Blackboard | None = None, remap: Mapping[str, str] | None = None,
                 autoremap: bool = False, values: Mapping[str, Any] | None = None) -> None:
        self.parent = parent
        self.remap = dict(remap or {})
        self.autoremap = autoremap and parent is not None
        self._local: dict[str, Any] = dict(values or {})
        self._versions: dict[str, int] = dict.fromkeys(self._local, 1)
        self._types: dict[str, str] = {}
        #: entries a script's ``:=`` created: BT.CPP gives them no type (``AnyTypeAllowed``)
        self._script_made: set[str] = set()
        self._emptied: set[str] = set()  # entries SetBlackboard's text left empty (typed ``BT::Any`` since)

    @classmethod
    def for_subtree(cls, parent: Blackboard, ports: Mapping[str, str]) -> Blackboard:
        """The blackboard of a SubTree node with these ports (``ID`` and other attributes are not ports)."""
        remap, values = {}, {}
        for port, text in ports.items():
            if port in COMMON_ATTRIBUTES:
                continue
            key = bare_key(text)
            if key == "=":
                remap[port] = port
            elif key is not None:
                remap[port] = key
            else:
                values[port] = subtree_literal(text)
        autoremap = ports.get("_autoremap", "false").strip().lower() in ("true", "1", "yes")
        return cls(parent, remap, autoremap, values)

    def _route(self, key: str) -> tuple[Blackboard, str]:
        if key[:1] == "@":  # the root blackboard's key, as in BT.CPP
            board = self
            while board.parent is not None:
                board = board.parent
            return board, key[1:]
        if key in self.remap and self.parent is not None:
            return self.parent._route(self.remap[key])
        if key in self._local or not self.autoremap or key[:1] == "_":  # BT.CPP: a ``_private`` key stays local
            return self, key
        return self.parent._route(key)  # type: ignore[union-attr]

    def __getitem__(self, key: str) -> Any:
        board, name = self._route(key)
        return board._local[name]

    def __setitem__(self, key: str, value: Any) -> None:
        """Write ``value``; text written to a typed entry is converted (raises ``PortError``)."""
        board, name = self._route(key)
        if type(value) is str and name in board._types:
            value = from_blackboard(value, board._types[name])
        board._local[name] = value
        board._versions[name] = board._versions.get(name, 0) + 1

    def declare(self, key: str, kind: str) -> None:
        """Make the entry ``key`` for a port of type ``kind`` that uses it, as BT.CPP does when it loads a tree: the
        first port gives it its type (``any``: none); a second of another type is refused unless either is untyped
        or the first was a string's."""
        board, name = self._route(key)
        known = board._types.get(name)
        if not compatible(known, kind):
            raise PortError(type_conflict(key, known, kind))  # type: ignore[arg-type]
        board._types.setdefault(name, kind)  # the first port makes the entry (``any``: untyped)

    def made_by_script(self, key: str) -> None:
        """Note that a script's ``:=`` created the entry ``key`` (BT.CPP: an entry of no type)."""
        board, name = self._route(key)
        if name not in board._types:
            board._script_made.add(name)

    def text_over_untyped(self, key: str) -> str:
        """What BT.CPP's SetBlackboard does writing text to ``key``: ``"write"`` it; ``"empty"`` an entry a script
        created (no converter parses the text: the entry is left empty and the next read of it fails; it now has the
        type ``BT::Any``); ``"refuse"`` one so emptied before (BT.CPP throws: no converter for ``BT::Any``)."""
        board, name = self._route(key)
        if name in board._script_made and name not in board._types:
            board._local.pop(name, None)
            board._types[name] = ANY
            board._script_made.discard(name)
            board._emptied.add(name)
            board._versions[name] = board._versions.get(name, 0) + 1
            return "empty"
        return "refuse" if name in board._emptied else "write"

    def has_entry(self, key: str) -> bool:
        """Whether the entry exists: written, or made by a port that uses it (a script may assign it with ``=``)."""
        board, name = self._route(key)
        return name in board._local or name in board._types

    def type_of(self, key: str) -> str | None:
        """The type a port gave the entry, None when none did (or an untyped one)."""
        board, name = self._route(key)
        kind = board._types.get(name)
        return None if kind == ANY else kind

    def version(self, key: str) -> int:
        """How many times ``key`` was written (0: never), as BehaviorTree.CPP's entry sequence id."""
        board, name = self._route(key)
        return board._versions.get(name, 0) if name in board._local else 0

    def __delitem__(self, key: str) -> None:
        board, name = self._route(key)
        del board._local[name]

    def __contains__(self, key: object) -> bool:
        if not isinstance(key, str):
            return False
        board, name = self._route(key)
        return name in board._local

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(k for k in {*self._local, *self.remap, *(self.parent or {} if self.autoremap else {})}
                           if k in self))

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __repr__(self) -> str:
        return f"Blackboard({dict(self.items())!r})"
