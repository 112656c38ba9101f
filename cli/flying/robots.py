"""``--robot KIND``: which kind of robot ``aeroexec run`` and ``verify`` drive (``drone`` by default).

A kind other than the built-in drone comes from an installed plugin (the entry point group ``aeroexec.robots``):
its catalog, behaviors, processes, own-state beliefs, simulated robot, default world and engine settings.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Any

from aeroexec.cli.catalog import chosen_catalog
from aeroexec.engine.catalog import BehaviorCatalog, load_catalog
from aeroexec.engine.robots import DRONE, RobotKind, RobotKindError, robot_kind


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--robot", default=DRONE, metavar="KIND",
                        help="the kind of robot: drone (default), or one an installed plugin adds, e.g. rover")


@dataclass
class RobotChoice:
    """The chosen kind (None: the built-in drone) and what the engine is built with for it."""

    kind: RobotKind | None

    def catalog(self, path: str | None) -> BehaviorCatalog:
        """The ``--catalog`` given, else the kind's, as the kind's behaviors serve it; raises CatalogError."""
        if self.kind is None:
            return chosen_catalog(path)
        catalog = load_catalog(path or self.kind.catalog)
        return catalog.served_by(self.library().names())

    def library(self) -> Any:
        return self.kind.behaviors() if self.kind is not None and self.kind.behaviors else None

    def engine_options(self, robot: Any) -> dict[str, Any]:
        """The Engine keyword arguments of this kind for ``robot``."""
        if self.kind is None:
            return {}
        options: dict[str, Any] = {"library": self.library(), "settings": self.kind.settings()}
        if self.kind.catalog is not None:
            options["described_in"] = load_catalog(self.kind.catalog)
        if self.kind.processes is not None:
            options["processes"] = self.kind.processes()
        if self.kind.telemetry is not None:
            options["telemetry"] = self.kind.telemetry(robot)
        return options


def chosen(args: argparse.Namespace) -> RobotChoice:
    """The robot kind of ``--robot``; raises RobotKindError with a sentence for the operator."""
    return RobotChoice(robot_kind(getattr(args, "robot", DRONE)))


__all__ = ["RobotChoice", "RobotKindError", "add_arguments", "chosen"]
