"""Entry points: how every table open to other packages (behaviors, processes, updaters, drone adapters,
contingencies) finds what an installed distribution adds, read once a process and loaded by group.

It imports nothing of aeroexec, so any layer may use it (the behavior library's registry, the catalog's table of
contingencies).
"""

from __future__ import annotations

import functools
import logging
from importlib.metadata import EntryPoints, entry_points
from typing import Any

logger = logging.getLogger(__name__)


@functools.cache
def installed() -> EntryPoints:
    """Every installed package's entry points, read once a process: reading them scans every installed package
    (~5 ms each time), and a flight asks for several groups (behaviors, processes, updaters, drones,
    contingencies). ``installed.cache_clear()`` reads them again (a distribution added to ``sys.path``)."""
    return entry_points()


def plugins(group: str, named: bool = False) -> list[tuple[str, Any]]:
    """The loaded entry points of ``group`` as (origin, object), or (name, object) when ``named``, by name; one
    that cannot be loaded is logged and left out, never takes the engine down."""
    found = []
    for point in sorted(installed().select(group=group), key=lambda p: p.name):
        try:
            found.append((point.name if named else f"entry point {point.name} = {point.value}", point.load()))
        except Exception as exc:
            logger.error("the %s plugin %s (%s) cannot be loaded: %s", group, point.name, point.value, exc)
    return found


__all__ = ["installed", "plugins"]
