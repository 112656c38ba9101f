"""Robot kinds: what the engine needs to drive one kind of robot, found by name (``aeroexec run --robot NAME``).

A kind bundles its behavior catalog, its behaviors and capability processes, the updater of its beliefs about
itself, its simulated robot and the engine settings it needs. ``drone`` is built in (the aerial catalog and
library, the simulated multicopter); packages add kinds through the entry point group ``aeroexec.robots`` (a
callable returning a :class:`RobotKind`), as ``examples/rover`` does.
"""

from __future__ import annotations

import functools
import logging
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.plugins import entry_points_of, load_reference, reference_of

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # the engine's modules are imported when a kind's engine is made, not to name a kind (verify)
    from typing import Any

    from aeroexec.engine.execution.process import BehaviorLibrary, EngineSettings
    from aeroexec.engine.execution.resources import ProcessRegistry

logger = logging.getLogger(__name__)

ROBOTS_GROUP = "aeroexec.robots"
DRONE = "drone"


class RobotKindError(ValueError):
    """No robot kind of that name, or a plugin that does not give one."""


def engine_settings() -> EngineSettings:
    """The engine's default settings (:class:`~aeroexec.engine.execution.process.EngineSettings`): a kind's unless
    it says otherwise."""
    from aeroexec.engine.execution.process import EngineSettings

    return EngineSettings()


@dataclass
class RobotKind:
    """One kind of robot the engine can drive."""

    name: str
    description: str
    catalog: Path | None = None  # its behavior catalog (None: the aerial one)
    behaviors: Callable[[], BehaviorLibrary] | None = None  # None: the aerial library and plugins
    processes: Callable[[], ProcessRegistry] | None = None  # None: the aerial processes and plugins
    simulator: Callable[[Any, int], Any] | None = None  # (world, seed) -> a simulated robot
    telemetry: Callable[[Any], Any] | None = None  # robot -> the updater of its own beliefs (None: a drone's)
    world: Path | None = None  # its default world file (None: the built-in field)
    settings: Callable[[], EngineSettings] = field(default=engine_settings)


def robot_kinds() -> dict[str, Callable[[], RobotKind]]:
    """Every robot kind installed, by name (``drone`` is built in)."""
    kinds: dict[str, Callable[[], RobotKind]] = {}
    for name, value in sorted(entry_points_of(ROBOTS_GROUP)):
        kinds[name] = functools.partial(load_reference, reference_of(value))
    return kinds


def robot_kind(name: str) -> RobotKind | None:
    """The robot kind called ``name``; None for the built-in drone. Raises :class:`RobotKindError`."""
    if name == DRONE:
        return None
    kinds = robot_kinds()
    if name not in kinds:
        known = ", ".join([DRONE, *sorted(kinds)])
        raise RobotKindError(f"--robot {name}: no such robot kind is installed (known: {known})")
    try:
        provider = kinds[name]()
        kind = provider() if callable(provider) and not isinstance(provider, RobotKind) else provider
    except Exception as error:  # a broken plugin is reported in words
        raise RobotKindError(f"--robot {name}: the plugin cannot be loaded: {error}") from None
    if not isinstance(kind, RobotKind):
        raise RobotKindError(f"--robot {name}: the plugin gives no RobotKind")
    return kind


_UNKNOWN_BEHAVIOR = r"The behavior (\S+) does not exist"  # compiled on first use (re's cache): not at every start


def robot_kind_hint(messages: Iterable[str]) -> str | None:
    """When behaviors a mission's check found unknown (``The behavior X does not exist``) belong to an installed
    robot kind, as when ``--robot rover`` is forgotten: which kind, and the option to give; None otherwise."""
    unknown = list(dict.fromkeys(m.group(1) for text in messages if (m := re.search(_UNKNOWN_BEHAVIOR, text))))
    if not unknown:
        return None
    best, known = None, []
    for name, behaviors in _kinds_behaviors().items():
        knows = [b for b in unknown if b in behaviors]
        if len(knows) > len(known):
            best, known = name, knows
    if best is None:
        return None
    what = "is a behavior" if len(known) == 1 else "are behaviors"
    return f"{', '.join(known)} {what} of the robot kind {best}: give --robot {best}" + \
        (" (the default)" if best == DRONE else "")


def _kinds_behaviors() -> dict[str, set[str]]:
    """The behaviors each installed robot kind's catalog describes (the drone's first); kinds that cannot be
    loaded are left out."""
    from aeroexec.engine.catalog import default_catalog, load_catalog
    from aeroexec.engine.errors import CatalogError

    kinds = {DRONE: set(default_catalog().behaviors)}
    for name in robot_kinds():
        try:
            kind = robot_kind(name)
            kinds[name] = set(load_catalog(kind.catalog).behaviors) if kind and kind.catalog else kinds[DRONE]
        except (RobotKindError, CatalogError, OSError):
            continue
    return kinds
