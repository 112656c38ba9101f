"""The simulated drones flying in one world: each one's cameras see the others as moving objects (shape ``drone``).

A fleet run in one process puts its drones in one :class:`Airspace`; a drone alone has none.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from aeroexec.drones.interface import Vector


class Airspace:
    """Who flies where in one world, by name; thread-safe."""

    def __init__(self) -> None:
        self._where: dict[str, Callable[[], Vector]] = {}
        self._lock = threading.Lock()

    def add(self, name: str, position: Callable[[], Vector]) -> None:
        """A drone called ``name`` whose true position ``position()`` tells."""
        with self._lock:
            if name in self._where:
                raise ValueError(f"two drones are called {name} in one airspace")
            self._where[name] = position

    def remove(self, name: str) -> None:
        with self._lock:
            self._where.pop(name, None)

    def names(self) -> list[str]:
        with self._lock:
            return sorted(self._where)

    def others(self, name: str) -> list[tuple[str, Vector]]:
        """Every other drone and where it is now."""
        with self._lock:
            where = [(other, position) for other, position in self._where.items() if other != name]
        return [(other, position()) for other, position in where]
