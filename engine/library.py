"""The library registry: where the engine finds behavior implementations and capability processes.

The aerial library (:mod:`aeroexec.engine.behaviors`) is one provider among
others. Providers are found by name, never imported by the engine's core:

- Python entry points in the groups ``aeroexec.behaviors`` (a callable
  returning a :class:`BehaviorLibrary` or an iterable of
  :class:`BehaviorProcess` classes) and ``aeroexec.processes`` (a callable
  returning a :class:`ProcessRegistry` or a mapping of process names to
  factories), so an installed package adds behaviors without editing aeroexec;
  ``aeroexec.updaters`` (a callable ``(drone)`` returning a :class:`BeliefUpdater`
  or an iterable of them) and ``aeroexec.drones`` (named by the ``--drone NAME:ADDRESS``
  scheme: a callable ``(address)`` returning a :class:`Drone`);
- ``module:attribute`` references, as ``aeroexec run --library / --processes /
  --updater`` pass them.

The names the aerial library serves are kept in the user's cache folder (:func:`behavior_names`), so ``aeroexec
verify`` says which behaviors have no implementation without importing the behaviors (~25 ms: bench/startup.py).
"""

from __future__ import annotations

import logging
import os
import sys
from collections.abc import Iterable, Mapping

from aeroexec import cache, plugins

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # imported where they are used: verify asks for the behaviors' names only (behavior_names)
    from typing import Any

    from aeroexec.beliefs import BeliefUpdater
    from aeroexec.drones import Drone
    from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess
    from aeroexec.engine.execution.resources import ProcessRegistry

logger = logging.getLogger(__name__)

BEHAVIORS_GROUP = "aeroexec.behaviors"
PROCESSES_GROUP = "aeroexec.processes"
UPDATERS_GROUP = "aeroexec.updaters"
DRONES_GROUP = "aeroexec.drones"
AERIAL_BEHAVIORS = "aeroexec.engine.behaviors:aerial_behaviors"
AERIAL_PROCESSES = "aeroexec.engine.behaviors:aerial_processes"
AERIAL_INDEX = "aeroexec.engine.behaviors:aerial_module_index"
AERIAL_PROCESSES_OF = "aeroexec.engine.behaviors:processes_of_module"


class LibraryError(plugins.PluginError):
    """A ``module:attribute`` reference or a plugin that does not give behaviors or processes."""


def load_reference(reference: str) -> Any:
    """The object named by ``module:attribute`` (``module.sub:obj.attr`` reads attributes in turn)."""
    return plugins.load_reference(reference, LibraryError)


def _produce(provider: Any, origin: str) -> Any:
    if not callable(provider) or isinstance(provider, type):
        return provider
    try:
        return provider()
    except Exception as exc:  # a plugin's mistake is reported by its name, not as a traceback
        raise LibraryError(f"{origin} failed: {type(exc).__name__}: {exc}") from None


def behaviors_of(provider: Any, origin: str) -> list[type[BehaviorProcess]]:
    """The behavior classes a provider gives: a library, classes, or a callable returning either."""
    from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess

    produced = _produce(provider, origin)
    if isinstance(produced, type) and issubclass(produced, BehaviorProcess):
        produced = [produced]
    if isinstance(produced, BehaviorLibrary):
        return [cls for name in sorted(produced.names()) if (cls := produced.get(name)) is not None]
    if isinstance(produced, Iterable) and not isinstance(produced, str | bytes | Mapping):
        classes = list(produced)
        bad = [c for c in classes if not (isinstance(c, type) and issubclass(c, BehaviorProcess))]
        if not bad:
            return classes
    raise LibraryError(f"{origin} gives no behaviors (a BehaviorLibrary or BehaviorProcess classes are expected)")


def processes_of(provider: Any, origin: str) -> dict[str, Any]:
    """The process factories a provider gives: a registry, a mapping, or a callable returning either."""
    from aeroexec.engine.execution.resources import ProcessRegistry

    produced = _produce(provider, origin)
    if isinstance(produced, ProcessRegistry):
        return produced.factories()
    if isinstance(produced, Mapping):
        return dict(produced)
    raise LibraryError(f"{origin} gives no processes (a ProcessRegistry or a mapping of names is expected)")


def default_library(extra: Iterable[str] = ()) -> BehaviorLibrary:
    """The aerial behaviors, every installed plugin's, then those of ``extra`` references (later names win). The
    aerial behaviors are known by their modules (:func:`aerial_index`), each imported when one of its behaviors is
    first asked for: a run imports the behaviors it uses."""
    from aeroexec.engine.execution.process import BehaviorLibrary

    library = BehaviorLibrary()
    for name, module in aerial_index()[0].items():
        library.served_by_module(name, module)
    for origin, provider in _other_providers(extra):
        for cls in behaviors_of(provider, origin):
            library.register(cls)
    return library


def _other_providers(extra: Iterable[str]) -> list[tuple[str, Any]]:
    """Every installed plugin's behavior providers, then those of ``extra`` references, as (origin, provider)."""
    return [*plugins.installed_plugins(BEHAVIORS_GROUP),
            *((reference, load_reference(reference)) for reference in extra)]


def _library(providers: Iterable[tuple[str, Any]]) -> BehaviorLibrary:
    from aeroexec.engine.execution.process import BehaviorLibrary

    library = BehaviorLibrary()
    for origin, provider in providers:
        for cls in behaviors_of(provider, origin):
            library.register(cls)
    return library


def behavior_names(extra: Iterable[str] = ()) -> set[str]:
    """The names :func:`default_library` serves with ``extra``, the aerial library's read from the user's cache
    folder when its modules are as they were (:func:`aerial_behavior_names`): a plugin's and ``extra``'s are loaded
    as the library loads them (raising :class:`LibraryError` alike)."""
    others = _other_providers(extra)
    return aerial_behavior_names() | (_library(others).names() if others else set())


def _search_path(package: str) -> list[str]:
    """The folders of ``package``'s modules, without importing it (its path as extended when it is imported)."""
    if package in sys.modules:
        return list(getattr(sys.modules[package], "__path__", []))
    import importlib.util

    spec = importlib.util.find_spec(package)
    return list(spec.submodule_search_locations or []) if spec is not None else []


def aerial_behavior_names() -> frozenset[str]:
    """The behaviors the aerial library (:data:`AERIAL_BEHAVIORS`) implements (:func:`aerial_index`)."""
    return frozenset(aerial_index()[0])


def aerial_index() -> tuple[dict[str, str], dict[str, str]]:
    """The module implementing each behavior of the aerial library and the module listing each of its capability
    processes (``aeroexec.engine.behaviors.aerial``'s ``aerial_module_index``), without importing them when its
    package's modules are those the index was last read from: it is kept in the user's cache folder under a hash of
    those modules' names, sizes and modification times (every folder of the package's path), aeroexec's version and
    Python's, and read from the library itself (then kept) when there is none."""
    folders = tuple(_search_path(AERIAL_BEHAVIORS.partition(":")[0]))
    # read once while the modules are as they were (the catalog's check, the library and the processes ask)
    seen = (folders, _modules_seen(folders), os.environ.get("XDG_CACHE_HOME"), os.environ.get("HOME"))
    if seen not in _indexes:
        _indexes.clear()
        _indexes[seen] = _read_aerial_index(seen[1])
    behaviors, processes = _indexes[seen]
    return dict(behaviors), dict(processes)


_indexes: dict[tuple[Any, ...], tuple[dict[str, str], dict[str, str]]] = {}


def _modules_seen(folders: tuple[str, ...]) -> tuple[tuple[str, int, int], ...]:
    """Each module of ``folders`` with its modification time and size."""
    seen = []
    for folder in folders:
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for entry in entries:
            if entry.name.endswith(".py"):
                try:
                    info = entry.stat()
                except OSError:
                    continue
                seen.append((entry.path, info.st_mtime_ns, info.st_size))
    return tuple(sorted(seen))


def _read_aerial_index(seen: tuple[tuple[str, int, int], ...]) -> tuple[dict[str, str], dict[str, str]]:
    import aeroexec

    # the modules' sizes and times, as the interpreter decides whether their bytecode is still theirs (and as a
    # catalog's reading code is stamped): hashing their bytes was ~2 ms of every start
    digest = cache.sha256(repr((AERIAL_BEHAVIORS, AERIAL_INDEX, aeroexec.__version__, sys.version_info[:2],
                                seen)).encode())
    key = f"behaviors.{digest.hexdigest()[:32]}.txt"
    data = cache.kept(key)
    if data is not None:
        index: tuple[dict[str, str], dict[str, str]] = ({}, {})
        lines = [line.split() for line in data.decode("utf-8", "replace").splitlines()]
        if all(len(words) == 3 and words[0] in ("behavior", "process") for words in lines):
            for kind, name, module in lines:
                index[kind == "process"][name] = module
            return index
    behaviors, processes = load_reference(AERIAL_INDEX)()
    cache.keep(key, "\n".join([*(f"behavior {name} {module}" for name, module in sorted(behaviors.items())),
                               *(f"process {name} {module}" for name, module in processes.items())]).encode())
    return behaviors, processes


class _ListedProcess:
    """A capability process of the aerial library: its module (of ``aeroexec.engine.behaviors.aerial``'s
    ``PROCESS_MODULES``) is imported when the process is first made."""

    __slots__ = ("module", "name")

    def __init__(self, module: str, name: str) -> None:
        self.module, self.name = module, name

    def __call__(self, name: str) -> Any:
        return load_reference(AERIAL_PROCESSES_OF)(self.module)[self.name](name)

    def __repr__(self) -> str:
        return f"<the process {self.name} of aeroexec.engine.behaviors.{self.module}>"


def default_processes(extra: Iterable[str] = ()) -> ProcessRegistry:
    """The aerial capability processes (each module imported when one of its processes is first made:
    :func:`aerial_index`), every installed plugin's, then those of ``extra`` references."""
    from aeroexec.engine.execution.resources import ProcessRegistry

    registry = ProcessRegistry({name: _ListedProcess(module, name) for name, module in aerial_index()[1].items()})
    providers = list(plugins.installed_plugins(PROCESSES_GROUP))
    providers += [(reference, load_reference(reference)) for reference in extra]
    for origin, provider in providers:
        for name, factory in processes_of(provider, origin).items():
            registry.register(name, factory)
    return registry


def updaters_of(provider: Any, drone: Drone, origin: str) -> list[BeliefUpdater]:
    """The belief updaters a provider gives: an updater, or a callable ``(drone)`` returning one or several."""
    from aeroexec.beliefs import BeliefUpdater

    produced = provider
    if not isinstance(provider, BeliefUpdater) and callable(provider):
        try:
            produced = provider(drone)
        except Exception as exc:
            raise LibraryError(f"{origin} cannot make its belief updaters: {type(exc).__name__}: {exc}") from None
    if isinstance(produced, BeliefUpdater):
        return [produced]
    if isinstance(produced, Iterable) and not isinstance(produced, str | bytes | Mapping):
        updaters = list(produced)
        if all(isinstance(u, BeliefUpdater) for u in updaters):
            return updaters
    raise LibraryError(f"{origin} gives no belief updaters (a BeliefUpdater, or a callable (drone) returning "
                       f"BeliefUpdaters, is expected)")


def default_updaters(drone: Drone, extra: Iterable[str] = ()) -> list[BeliefUpdater]:
    """Every installed plugin's belief updaters, then those of ``extra`` references, for ``drone``."""
    providers = [*plugins.installed_plugins(UPDATERS_GROUP),
                 *((reference, load_reference(reference)) for reference in extra)]
    return [updater for origin, provider in providers for updater in updaters_of(provider, drone, origin)]


def drone_adapters() -> dict[str, Any]:
    """The installed drone adapters by scheme name (``aeroexec.drones`` entry points): ``(address) -> Drone``."""
    return dict(plugins.installed_plugins(DRONES_GROUP, named=True))


def make_drone(scheme: str, address: str) -> Drone:
    """A drone from an installed adapter (``--drone SCHEME:ADDRESS``); ``LibraryError`` when there is none."""
    adapters = drone_adapters()
    if scheme not in adapters:
        known = ", ".join(sorted(adapters)) or "none"
        raise LibraryError(f"no drone adapter is named {scheme!r} (installed: {known}; a package adds one with "
                           f"an {DRONES_GROUP} entry point)")
    try:
        drone = adapters[scheme](address)
    except Exception as exc:
        raise LibraryError(f"the drone adapter {scheme} cannot connect to {address!r}: "
                           f"{type(exc).__name__}: {exc}") from None
    from aeroexec.drones import Drone

    if not isinstance(drone, Drone):
        raise LibraryError(f"the drone adapter {scheme} gives {type(drone).__name__}, not a Drone")
    return drone


__all__ = ["LibraryError", "aerial_behavior_names", "aerial_index", "behavior_names", "default_library",
           "default_processes", "default_updaters", "drone_adapters",
           "load_reference", "make_drone"]
