"""The resource manager (paper section 4.4): runs the processes of the capabilities that active behaviors need.

Capabilities are reference-counted by behavior. One nobody references is
stopped after a grace period, so consecutive behaviors reuse its processes;
permanent ones run from the start; incompatible ones never run together; a
process that fails is replaced by the alternative the catalog names.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.events import EventLog

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)


class Process:
    """A software process that supports a capability (a controller, a detector, a planner).

    Subclasses override :meth:`on_start`, :meth:`step`, :meth:`on_stop` and
    :meth:`healthy`; the base class is a process with nothing to do.
    """

    def __init__(self, name: str) -> None:
        self.name = name
        self.running = False
        self.context: Any = None
        self.failure = ""  # why it failed, when it did

    def start(self, context: Any) -> None:
        self.context = context
        self.on_start()
        self.running = True

    def stop(self) -> None:
        if self.running:
            self.running = False
            self.on_stop()

    def on_start(self) -> None:
        """Start working (subscribe, open devices)."""

    def on_stop(self) -> None:
        """Stop working and release what was opened."""

    def step(self, now: float) -> None:
        """Do one period of work (called every engine tick while running)."""

    def healthy(self) -> bool:
        """False when the process has failed and must be replaced."""
        return True


ProcessFactory = Callable[[str], Process]
_OWN: dict[type, tuple[bool, bool]] = {}  # process class -> whether it has a step, a health check of its own


def _own(kind: type) -> tuple[bool, bool]:
    """Whether processes of class ``kind`` have a :meth:`~Process.step`, a :meth:`~Process.healthy` of their own
    (else they do nothing there, and are always healthy)."""
    own = _OWN[kind] = (kind.step is not Process.step, kind.healthy is not Process.healthy)
    return own


class ProcessRegistry:
    """Which Python object serves each process name; names without a factory get an idle :class:`Process`."""

    def __init__(self, factories: dict[str, ProcessFactory] | None = None) -> None:
        self._factories: dict[str, ProcessFactory] = dict(factories or {})

    def register(self, name: str, factory: ProcessFactory) -> None:
        self._factories[name] = factory

    def create(self, name: str) -> Process:
        return self._factories.get(name, Process)(name)

    def names(self) -> set[str]:
        return set(self._factories)

    def factories(self) -> dict[str, ProcessFactory]:
        return dict(self._factories)


@dataclass
class _Capability:
    name: str
    processes: list[Process] = field(default_factory=list)
    users: set[str] = field(default_factory=set)
    idle_since: float | None = None
    permanent: bool = False


class ResourceError(RuntimeError):
    """The capabilities of a behavior cannot be activated."""


class ResourceManager:
    """Starts and stops capability processes as behaviors need them."""

    def __init__(self, catalog: BehaviorCatalog, registry: ProcessRegistry, log: EventLog,
                 context: Any = None, grace: float = 2.0) -> None:
        self.catalog = catalog
        self.registry = registry
        self.log = log
        self.context = context
        self.grace = grace
        self._running: dict[str, _Capability] = {}
        # What a tick steps and checks (the processes with a step or a health check of their own, in order), made
        # again only when a capability starts, stops or has a process replaced: a tick with nothing started or
        # stopped reads one list instead of walking every capability (None: to be made again)
        self._work: list[tuple[str, _Capability, int, Process, bool, bool]] | None = None
        self._idle = False  # whether a capability may be in its grace period (released by its last user)

    # -- queries ----------------------------------------------------------------------
    def running(self) -> set[str]:
        """The capabilities whose processes run now (used or in their grace period)."""
        return set(self._running)

    def users(self, capability: str) -> set[str]:
        """The behaviors that reference ``capability``."""
        entry = self._running.get(capability)
        return set(entry.users) if entry else set()

    def processes(self, capability: str) -> list[Process]:
        entry = self._running.get(capability)
        return list(entry.processes) if entry else []

    # -- lifecycle ----------------------------------------------------------------------
    def start_permanent(self) -> None:
        """Start the permanent_active capabilities (at engine start)."""
        for descriptor in self.catalog.capabilities.values():
            if descriptor.permanent and descriptor.name not in self._running:
                self._start(descriptor.name, permanent=True)

    def acquire(self, behavior: str, capabilities: Iterable[str]) -> None:
        """Reference the capabilities for ``behavior``, starting what is not running; raises :class:`ResourceError`."""
        needed = list(dict.fromkeys(capabilities))
        for name in needed:
            for other, entry in list(self._running.items()):
                if other == name or not self._incompatible(name, other):
                    continue
                users = entry.users - {behavior}
                if users or entry.permanent:
                    holder = ", ".join(sorted(users)) or "permanent"
                    raise ResourceError(f"the capability {name} cannot run together with {other} (used by {holder})")
                self._stop(other, "incompatible with " + name)
        started = []
        try:
            for name in needed:
                if name not in self._running:
                    self._start(name)
                    started.append(name)
        except ResourceError:
            for name in started:
                self._stop(name, "its behavior could not start")
            raise
        for name in needed:
            entry = self._running[name]
            entry.users.add(behavior)
            entry.idle_since = None

    def release(self, behavior: str, now: float) -> None:
        """Drop ``behavior``'s references; capabilities nobody uses start their grace period."""
        for entry in self._running.values():
            if behavior in entry.users:
                entry.users.discard(behavior)
                if not entry.users and not entry.permanent:
                    entry.idle_since = now
                    self._idle = True

    def update(self, now: float) -> list[tuple[str, str]]:
        """One tick: stop idle capabilities, step processes, replace failed ones.

        Returns ``(capability, reason)`` for each capability that failed with no alternative;
        the coordinator stops the behaviors using it.
        """
        if self._idle:
            for name, entry in list(self._running.items()):
                if entry.idle_since is not None and now - entry.idle_since >= self.grace:
                    self._stop(name, f"unused for {self.grace:g} s")
            self._idle = any(entry.idle_since is not None for entry in self._running.values())
        work = self._work
        if work is None:
            work = self._work = self._plan()
        failed = []
        for name, entry, index, process, steps, checks in work:
            try:
                if steps:
                    process.step(now)
                ok = process.healthy() if checks else True
            except Exception as exc:  # a process that raises has failed
                logger.exception("process %s failed", process.name)
                ok, process.failure = False, str(exc)
            if not ok and not self._replace(name, entry, index, process):
                failed.append((name, f"process {process.name} failed"))
        for name, _ in failed:
            self._stop(name, "a process failed")
        return failed

    def _plan(self) -> list[tuple[str, _Capability, int, Process, bool, bool]]:
        """The processes a tick steps or checks, in the order of their capabilities' start (the others do nothing
        in a tick: no step, always healthy)."""
        work = []
        for name, entry in self._running.items():
            for index, process in enumerate(entry.processes):
                steps, checks = _OWN.get(type(process)) or _own(type(process))
                if steps or checks:
                    work.append((name, entry, index, process, steps, checks))
        return work

    def shutdown(self) -> None:
        """Stop every capability (engine stop)."""
        for name in list(self._running):
            self._stop(name, "engine stopped")

    # -- internals ----------------------------------------------------------------------
    def _incompatible(self, a: str, b: str) -> bool:
        da, db = self.catalog.capabilities.get(a), self.catalog.capabilities.get(b)
        return bool((da and b in da.incompatible) or (db and a in db.incompatible))

    def _start(self, name: str, permanent: bool = False) -> None:
        descriptor = self.catalog.capabilities.get(name)
        entry = _Capability(name, permanent=permanent)
        for process_name in descriptor.processes if descriptor else ():
            process = self._start_process(process_name, descriptor.alternatives.get(process_name))
            if process is None:
                for started in entry.processes:
                    started.stop()
                raise ResourceError(f"the capability {name} cannot be activated: process {process_name} "
                                    f"does not start")
            entry.processes.append(process)
        self._running[name] = entry
        self._work = None
        self.log.record("capability_started", detail=name,
                        processes=[p.name for p in entry.processes], permanent=permanent)

    def _start_process(self, name: str, alternative: str | None) -> Process | None:
        for candidate in (name, alternative):
            if candidate is None:
                continue
            process = self.registry.create(candidate)
            try:
                process.start(self.context)
                return process
            except Exception:
                logger.exception("process %s does not start", candidate)
                self.log.record("process_failed", detail=f"{candidate} does not start")
        return None

    def _replace(self, capability: str, entry: _Capability, index: int, process: Process) -> bool:
        descriptor = self.catalog.capabilities.get(capability)
        alternative = descriptor.alternatives.get(process.name) if descriptor else None
        self._safe_stop(process)
        if alternative is None:
            self.log.record("process_failed", detail=f"{process.name} of {capability}; no alternative")
            return False
        replacement = self._start_process(alternative, None)
        if replacement is None:
            return False
        entry.processes[index] = replacement
        self._work = None
        self.log.record("process_replaced", detail=f"{process.name} failed; {alternative} runs instead",
                        capability=capability)
        return True

    def _stop(self, name: str, reason: str) -> None:
        entry = self._running.pop(name, None)
        if entry is None:
            return
        self._work = None
        for process in reversed(entry.processes):
            self._safe_stop(process)
        self.log.record("capability_stopped", detail=f"{name} ({reason})")

    @staticmethod
    def _safe_stop(process: Process) -> None:
        try:
            process.stop()
        except Exception:
            logger.exception("process %s failed to stop", process.name)
