"""Plugins: objects named ``module:attribute`` and the installed packages' entry points, loaded one way for every
group (behaviors, processes, updaters, drones in :mod:`aeroexec.engine.library`; mission formats in
:mod:`aeroexec.trees.formats`). Imports nothing of aeroexec but ``aeroexec.lazy``, so a table of plugins costs no
engine to read."""

from __future__ import annotations

import functools
import importlib
import os
import sys

from aeroexec.lazy import lazy_logger

TYPE_CHECKING = False  # typing and logging are not imported until needed: ``aeroexec --help`` reads plugins
if TYPE_CHECKING:
    from importlib.metadata import EntryPoints
    from typing import Any

logger = lazy_logger(__name__)


class PluginError(ValueError):
    """A ``module:attribute`` reference that names nothing."""


def load_reference(reference: str, error: type[ValueError] = PluginError) -> Any:
    """The object named by ``module:attribute`` (``module.sub:obj.attr`` reads attributes in turn); ``error`` is
    raised, with what is wrong, when it names nothing."""
    module_name, sep, attribute = reference.partition(":")
    if not sep or not module_name or not attribute:
        raise error(f"{reference!r} is not a reference of the form module:attribute")
    try:
        target: Any = importlib.import_module(module_name)
    except ImportError as exc:
        raise error(f"{reference}: cannot import {module_name} ({exc})") from None
    for part in attribute.split("."):
        try:
            target = getattr(target, part)
        except AttributeError:
            raise error(f"{reference}: {module_name} has no attribute {attribute}") from None
    return target


@functools.cache
def installed() -> EntryPoints:
    """Every installed package's entry points, read once a process: reading them scans every installed package
    (~5 ms each time), and a flight asks for several groups (behaviors, processes, updaters, drones, formats)."""
    from importlib.metadata import entry_points  # imports email, zipfile, csv...: ~20 ms of every command's start

    return entry_points()


@functools.cache
def _groups_on_path(path: tuple[str, ...]) -> frozenset[str] | None:
    """The entry-point groups the installed packages name, read from the ``entry_points.txt`` of every
    ``*.dist-info`` and ``*.egg-info`` folder in the folders of ``path`` (``sys.path``: read again when it changes),
    where :mod:`importlib.metadata` finds them (~1 ms, without importing it). None when the path holds what only it
    reads (a zip file)."""
    groups: set[str] = set()
    for entry in path:
        folder = entry or "."
        try:
            names = os.listdir(folder)
        except NotADirectoryError:
            return None  # a zip on the path: importlib.metadata reads its metadata
        except OSError:
            continue
        for name in names:
            if not name.endswith((".dist-info", ".egg-info")):
                continue
            try:
                with open(os.path.join(folder, name, "entry_points.txt"), encoding="utf-8") as file:
                    groups.update(line.strip()[1:-1].strip() for line in file
                                  if line.lstrip().startswith("[") and line.rstrip().endswith("]"))
            except (OSError, UnicodeDecodeError):
                continue
    return frozenset(groups)


def entry_points_of(group: str) -> list[Any]:
    """The installed entry points of ``group``, read now (not loaded); none, without importing
    :mod:`importlib.metadata`, when no installed package names the group."""
    groups = _groups_on_path(tuple(sys.path))
    if groups is not None and group not in groups:
        return []
    from importlib.metadata import entry_points

    return list(entry_points(group=group))


def installed_plugins(group: str, named: bool = False) -> list[tuple[str, Any]]:
    """The loaded entry points of ``group`` as (origin, object), or (name, object) when ``named``; one that cannot
    be loaded is logged and left out."""
    found: list[tuple[str, Any]] = []
    groups = _groups_on_path(tuple(sys.path))
    if groups is not None and group not in groups:  # no package names the group: importlib.metadata is not imported
        return found
    for point in sorted(installed().select(group=group), key=lambda p: p.name):
        try:
            found.append((point.name if named else f"entry point {point.name} = {point.value}", point.load()))
        except Exception as exc:  # a broken plugin is reported, never takes the engine down
            logger.error("the %s plugin %s (%s) cannot be loaded: %s", group, point.name, point.value, exc)
    return found


__all__ = ["PluginError", "entry_points_of", "installed", "installed_plugins", "load_reference"]
