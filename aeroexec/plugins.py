"""Plugins: objects named ``module:attribute`` and the installed packages' entry points, loaded one way for every
group (behaviors, processes, updaters, drones in :mod:`aeroexec.engine.library`; mission formats in
:mod:`aeroexec.trees.formats`). Imports nothing of aeroexec but ``aeroexec.lazy``, so a table of plugins costs no
engine to read."""

from __future__ import annotations

import functools
import importlib
import os
import re
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
def _entries_on_path(path: tuple[str, ...]) -> dict[str, list[tuple[str, str]]] | None:
    """Every installed package's entry points by group, as (name, ``module:attribute``), read from the
    ``entry_points.txt`` of every ``*.dist-info`` and ``*.egg-info`` folder in the folders of ``path`` (``sys.path``:
    read again when it changes), where :mod:`importlib.metadata` finds them and as it reads them (a distribution
    found twice counts where it is first on the path), in ~1 ms and without importing it (~20 ms of every command's
    start). None when the path holds what only it reads (a zip file)."""
    groups: dict[str, list[tuple[str, str]]] = {}
    seen: set[str] = set()
    for entry in path:
        folder = entry or "."
        try:
            names = sorted(os.listdir(folder))
        except NotADirectoryError:
            return None  # a zip on the path: importlib.metadata reads its metadata
        except OSError:
            continue
        for name in names:
            if not name.endswith((".dist-info", ".egg-info")):
                continue
            distribution = re.sub(r"[-_.]+", "_", name.rsplit(".", 1)[0].split("-", 1)[0]).lower()
            try:
                with open(os.path.join(folder, name, "entry_points.txt"), encoding="utf-8") as file:
                    text = file.read()
            except (OSError, UnicodeDecodeError):
                continue
            if distribution in seen:
                continue
            seen.add(distribution)
            group = None
            for line in text.splitlines():
                line = line.strip()
                if not line or line.startswith(("#", ";")):
                    continue
                if line.startswith("[") and line.endswith("]"):
                    group = line[1:-1].strip()
                    groups.setdefault(group, [])
                elif group is not None and "=" in line:
                    key, value = line.split("=", 1)
                    groups[group].append((key.strip(), value.strip()))
    return groups


def entry_points_of(group: str) -> list[tuple[str, str]]:
    """The installed entry points of ``group`` as (name, ``module:attribute``), read now, not loaded: from the
    packages' ``entry_points.txt`` (:func:`_entries_on_path`), or through :mod:`importlib.metadata` when the path
    holds a zip file."""
    groups = _entries_on_path(tuple(sys.path))
    if groups is None:  # a zip on the path: importlib.metadata reads what is there
        return [(point.name, point.value) for point in installed().select(group=group)]
    return list(groups.get(group, []))


def reference_of(value: str) -> str:
    """The ``module:attribute`` of an entry point's value (``module:attribute [extra]``: the extra is pip's)."""
    return value.split("[", 1)[0].strip()


def installed_plugins(group: str, named: bool = False) -> list[tuple[str, Any]]:
    """The loaded entry points of ``group`` as (origin, object), or (name, object) when ``named``; one that cannot
    be loaded is logged and left out."""
    found: list[tuple[str, Any]] = []
    for name, value in sorted(entry_points_of(group)):
        try:
            found.append((name if named else f"entry point {name} = {value}", load_reference(reference_of(value))))
        except Exception as exc:  # a broken plugin is reported, never takes the engine down
            logger.error("the %s plugin %s (%s) cannot be loaded: %s", group, name, value, exc)
    return found


__all__ = ["PluginError", "entry_points_of", "installed", "installed_plugins", "load_reference", "reference_of"]
