"""The simulated drones flying in one world: each one's cameras see the others as moving objects (shape ``drone``).

A fleet puts its drones in one :class:`Airspace`; a drone alone has none. A fleet spread over processes (or
ticked in any order) gives it ``reported``: where each drone of the world last said it was, so that what a drone
sees does not depend on which drones were ticked before it, nor on the process that flies them.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping

from aeroexec.drones.interface import Vector


class Airspace:
    """Who flies where in one world, by name; thread-safe. ``reported()``: every drone of the world and where it
    last said it was, seen instead of where the drones added here are now."""

    def __init__(self, reported: Callable[[], Mapping[str, Vector]] | None = None) -> None:
        self._where: dict[str, Callable[[], Vector]] = {}
        self._reported = reported
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
        """Every other drone and where it is now (or last said it was)."""
        if self._reported is not None:
            return [(other, where) for other, where in self._reported().items() if other != name]
        with self._lock:
            where = [(other, position) for other, position in self._where.items() if other != name]
        return [(other, position()) for other, position in where]
