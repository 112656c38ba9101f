"""The blackboard of a tree run: a mapping of keys to values, scoped per SubTree with BehaviorTree.CPP's remapping.

A SubTree has a blackboard of its own. ``<SubTree ID="X" goal="{target}"/>`` maps the subtree's ``goal`` to the
parent's ``target`` (reads and writes go through); ``speed="1.5"`` sets a literal in the subtree;
``_autoremap="true"`` shares every other key with the parent under the same name.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, MutableMapping
from typing import Any

from aeroexec.trees.model import COMMON_ATTRIBUTES
from aeroexec.trees.ports import bare_key


class Blackboard(MutableMapping[str, Any]):
    """Keys and values of one tree scope; ``remap`` sends a key to the parent under another name."""

    def __init__(self, parent: Blackboard | None = None, remap: Mapping[str, str] | None = None,
                 autoremap: bool = False, values: Mapping[str, Any] | None = None) -> None:
        self.parent = parent
        self.remap = dict(remap or {})
        self.autoremap = autoremap and parent is not None
        self._local: dict[str, Any] = dict(values or {})
        self._versions: dict[str, int] = dict.fromkeys(self._local, 1)

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
                values[port] = text
        autoremap = ports.get("_autoremap", "false").strip().lower() in ("true", "1", "yes")
        return cls(parent, remap, autoremap, values)

    def _route(self, key: str) -> tuple[Blackboard, str]:
        if key in self.remap and self.parent is not None:
            return self.parent._route(self.remap[key])
        if key in self._local or not self.autoremap:
            return self, key
        return self.parent._route(key)  # type: ignore[union-attr]

    def __getitem__(self, key: str) -> Any:
        board, name = self._route(key)
        return board._local[name]

    def __setitem__(self, key: str, value: Any) -> None:
        board, name = self._route(key)
        board._local[name] = value
        board._versions[name] = board._versions.get(name, 0) + 1

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
