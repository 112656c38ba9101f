"""Missions that are scripts: a program with no ``mission()`` function that imports an API a dialect runs whole
(Aerostack2's: ``rclpy.init()``, ``DroneInterface("drone0")``, ``if __name__ == '__main__':``), run whole as
``__main__`` on the mission's thread.

The script runs unchanged; what it takes from its surroundings is the engine's. ``time.sleep``, ``time.time``
and ``time.monotonic`` (as the script imports them) wait on and read the engine's clock, so a simulated run is
paced by simulated time and a ``while ...: sleep(0.1)`` loop sees the world move; ``sys.argv`` holds the script
and the arguments it was given (``aeroexec run script.py -- ARGS``; none: its argparse defaults apply) and its
folder is on ``sys.path`` as when Python runs a script; its threads
(``threading.Thread``) are the mission's (:class:`MissionThread`); ``input()`` is a question for the operator
(:func:`ask_operator`); ``exit(0)`` ends it completed, another status fails it; the dialects' import finders are
installed (ROS modules it imports and never uses import as stand-ins: :mod:`.standins`). Each ``DroneInterface``
(Aerostack2's) binds to a drone by its namespace (:func:`drone_engine`); a script several drones of a fleet name
flies them all (:func:`fly_together`).
"""

from __future__ import annotations

import ast
import builtins
import contextlib
import importlib.machinery
import os
import re
import sys
import threading
import time
import types
import weakref
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path

from aeroexec.engine import api
from aeroexec.engine.errors import MissionAborted
from aeroexec.engine.missions import standins
from aeroexec.engine.missions.bridge import MissionStalled

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

_lock = threading.RLock()
_claimed: weakref.WeakKeyDictionary[Any, str] = weakref.WeakKeyDictionary()  # engine -> the namespace it flies as
_fleet: dict[str, Any] | None = None  # namespace -> engine, while a script drives a fleet


class ScriptExit(RuntimeError):
    """The script ended with ``exit(N)``, N not 0."""


class DroneNotFound(LookupError):
    """A drone interface names a drone this run does not fly."""


def is_script(tree: ast.Module, nodes: Iterable[ast.AST] | None = None) -> bool:
    """True for a script: no ``mission()``/``runMission()`` at top level, and an import of an API a dialect runs
    whole (Aerostack2's: :func:`.standins.script_names`), among ``nodes`` (the program's when already walked)."""
    if any(isinstance(n, ast.FunctionDef) and n.name in ("mission", "runMission") for n in tree.body):
        return False  # (the dialects' stand-ins are not loaded to say so)
    names_run_whole = standins.script_names()
    for node in ast.walk(tree) if nodes is None else nodes:
        names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                 [node.module] if isinstance(node, ast.ImportFrom) and node.module and not node.level else [])
        if any(name.split(".")[0] in names_run_whole for name in names):
            return True
    return False


@contextlib.contextmanager
def flying_fleet(engines: Mapping[str, Any]) -> Iterator[None]:
    """While a script drives several drones: each ``DroneInterface(namespace)`` binds to ``engines[namespace]``."""
    global _fleet
    with _lock:
        previous, _fleet = _fleet, dict(engines)
    try:
        yield
    finally:
        with _lock:
            _fleet = previous


def drone_engine(namespace: str) -> Any:
    """The engine flying the drone ``namespace``: in a fleet, the drone of that name; alone, the run's drone
    (whatever the script calls it: the first name it uses is the drone's for the run)."""
    with _lock:
        fleet = _fleet
    if fleet is not None:
        if namespace not in fleet:
            raise DroneNotFound(f"no drone named {namespace} in this fleet (its drones: {', '.join(fleet)})")
        return fleet[namespace]
    engine = api.current_engine()
    with _lock:
        claimed = _claimed.setdefault(engine, namespace)
    if claimed != namespace:
        raise DroneNotFound(f"the script drives drone {namespace} besides {claimed}, and this run flies one drone: "
                            f"fly it as a fleet, one drone per namespace")
    return engine


class _EngineTime(types.ModuleType):
    """``time`` as a script sees it: the engine's clock; the rest of the module as it is."""

    def __init__(self) -> None:
        super().__init__("time", time.__doc__)
        self._started = time.time()

    def __getattr__(self, name: str) -> Any:
        return getattr(time, name)

    def sleep(self, seconds: float) -> None:
        api.wait(max(0.0, float(seconds)))

    def time(self) -> float:
        return self._started + api.now()

    def monotonic(self) -> float:
        return api.now()

    perf_counter = monotonic


_CHOICES = r"\(([^()/]+(?:/[^()/]+)+)\)"  # compiled on the first question (re's cache), not at every start


def ask_operator(prompt: Any = "") -> str:
    """``input()`` as a script sees it: a question for the operator (ASK_OPERATOR), answered at the terminal,
    from ``--answers``, through ``aeroexec ctl answer`` or the console, or with its first possible answer when
    nobody is there; ``(y/n)`` in the prompt gives the possible answers."""
    question = str(prompt).strip()
    found = re.search(_CHOICES, question)
    answers = [a.strip() for a in found.group(1).split("/")] if found else []
    arguments = {"question": question or "input", **({"possible_answers": answers} if answers else {})}
    answer = api.ask_behavior("ASK_OPERATOR", **arguments)
    if answer is None:
        raise EOFError(f"the operator did not answer {question!r}")
    return str(answer)


class MissionThread(threading.Thread):
    """``threading.Thread`` as a script sees it: a thread of the mission, bound to the engine of the thread that
    started it; the mission runs (simulated time waits for it) while one of its threads runs Python code."""

    def start(self) -> None:
        self._engine = api.current_engine()
        self._engine.bridge.thread_started(self)
        try:
            super().start()
        except BaseException:
            self._engine.bridge.thread_ended(self)
            raise

    def run(self) -> None:
        api.bind(self._engine)
        try:
            super().run()
        except (MissionAborted, MissionStalled):
            pass  # the flight ended while this thread waited on it; or it polled on as the mission's thread does
        finally:
            api.unbind()
            self._engine.bridge.thread_ended(self)  # its joiners run from here on, however late they wake

    def join(self, timeout: float | None = None) -> None:
        bridge = getattr(getattr(self, "_engine", None), "bridge", None)
        if bridge is None or threading.current_thread() is self or not bridge.joining(self):
            return super().join(timeout)
        try:
            super().join(timeout)
        finally:
            bridge.joined(self)


class _MissionThreading(types.ModuleType):
    """``threading`` as a script sees it: its threads are the mission's (:class:`MissionThread`)."""

    Thread = MissionThread

    def __init__(self) -> None:
        super().__init__("threading", threading.__doc__)

    def __getattr__(self, name: str) -> Any:
        return getattr(threading, name)


def _builtins(engine_time: types.ModuleType) -> dict[str, Any]:
    real_import = standins.mission_import()  # the mission APIs under the names the script imports
    mission_threading = _MissionThreading()

    def import_(name: str, globals: Any = None, locals: Any = None, fromlist: Any = (), level: int = 0) -> Any:
        module = real_import(name, globals, locals, fromlist, level)
        if level == 0 and name in ("time", "threading"):
            return engine_time if name == "time" else mission_threading
        return module

    return {**vars(builtins), "__import__": import_, "input": ask_operator}


class _SiblingLoader:  # importlib.abc.Loader's protocol, without importing importlib.abc (see SiblingModules)
    """Runs a module of the script's folder as the script runs: with the script's builtins (its imports served as
    the script's are, its time and threads the engine's)."""

    def __init__(self, loader: Any, scope_builtins: dict[str, Any]) -> None:
        self.loader, self.scope_builtins = loader, scope_builtins

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType | None:
        return None

    def exec_module(self, module: types.ModuleType) -> None:
        code = self.loader.get_code(module.__name__)
        module.__dict__["__builtins__"] = self.scope_builtins
        exec(code, module.__dict__)


class SiblingModules:
    """Finds the modules of a script's folder (``from mission import ...`` beside ``mission_swarm.py``) first, and
    loads them as the script is run (:class:`_SiblingLoader`); :meth:`close` forgets the modules it loaded.

    A finder of ``importlib.abc.MetaPathFinder``'s protocol (``find_spec``), not its subclass: importing
    :mod:`importlib.abc` imports importlib.resources, tempfile, shutil and random (~5 ms of every run's start)."""

    def __init__(self, folder: str, scope_builtins: dict[str, Any]) -> None:
        self.folder, self.scope_builtins = str(Path(folder).resolve()), scope_builtins
        self.loaded: list[str] = []

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        if path is None and "." in fullname:
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, [self.folder] if path is None else path)
        if spec is None or not spec.origin or not spec.origin.endswith(".py") or \
                not str(Path(spec.origin).resolve()).startswith(self.folder + os.sep):
            return None
        spec.loader = _SiblingLoader(spec.loader, self.scope_builtins)
        self.loaded.append(fullname)
        return spec

    def close(self) -> None:
        with contextlib.suppress(ValueError):
            sys.meta_path.remove(self)
        for name in self.loaded:
            sys.modules.pop(name, None)


class ScriptMission:
    """The script in ``path`` as a mission function: calling it runs the script whole as ``__main__`` (see the
    module's docstring)."""

    def __init__(self, path: Path, source: str, args: tuple[str, ...] = ()) -> None:
        self.path = Path(path)
        self.code = compile(source, str(path), "exec")
        self.args = tuple(args)

    def __call__(self) -> None:
        standins.install_finders()
        folder = str(self.path.resolve().parent)
        scope = {"__name__": "__main__", "__file__": str(self.path), "__builtins__": _builtins(_EngineTime())}
        siblings = SiblingModules(folder, scope["__builtins__"])  # its modules import as under python3
        sys.meta_path.insert(0, siblings)
        environment = standins.script_environment()  # Aerostack2's: the simulated drone's namespace
        saved = sys.argv, list(sys.path), {key: os.environ.get(key) for key in environment}
        sys.argv = [str(self.path), *self.args]
        if folder not in sys.path:
            sys.path.insert(0, folder)
        for key, value in environment.items():
            os.environ.setdefault(key, value)
        try:
            exec(self.code, scope)
        except SystemExit as end:
            if end.code not in (None, 0):
                raise ScriptExit(f"the script exited with status {end.code}") from None
        finally:
            siblings.close()
            sys.argv, sys.path[:] = saved[0], saved[1]
            for key, value in saved[2].items():
                if value is None:
                    os.environ.pop(key, None)


def script_mission(path: Path, source: str, args: tuple[str, ...] = ()) -> ScriptMission:
    """The script in ``path`` (its ``source``) as a mission function, given the arguments ``args``."""
    return ScriptMission(path, source, args)


def fly_together(engines: Mapping[str, Any], mission: Callable[[], Any], name: str) -> threading.Thread:
    """Start one mission that drives several drones (``engines`` by namespace): it runs once, on the first engine's
    mission thread, each ``DroneInterface`` bound to its drone; every engine sees it run, wait and end as its own
    mission (its log says when it started and how it ended)."""
    first, *others = list(engines.values())
    first.bridge.share_mission(e.bridge for e in others)
    for engine in others:
        engine.log.record("mission_started", detail=name)

    def mirror(event: Any) -> None:  # how the mission ended, in every drone's log
        if event.kind in ("mission_completed", "mission_failed"):
            for engine in others:
                engine.log.record(event.kind, detail=event.detail)

    first.log.subscribe(mirror)

    def run() -> None:
        with flying_fleet(engines):
            mission()

    return first.start_mission(run, name)


__all__ = ["DroneNotFound", "MissionThread", "ScriptExit", "ScriptMission", "ask_operator",
           "drone_engine", "fly_together", "flying_fleet", "is_script", "script_mission"]
