"""The Python mission API (paper section 6.1, Table 8): what a mission program calls, from its own thread.

``import aeroexec.engine.api as api`` then ``api.execute_behavior("TAKE_OFF")``.
The paper's and Aerostack's spellings are aliases (``executeBehavior``,
``consultBelief``, ``startTask``...). Argument names match the catalog without
regard to case: ``coordinates=`` is ``COORDINATES``. Reserved keywords:
``timeout=`` (seconds, overrides the catalog's), and for recurrent behaviors
``activation_delay=``, ``activation_distance=((x, y, z), meters)`` and
``activation_yaw=(min, max)`` (Appendix A's activation conditions).
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import os
import sys
import threading
import traceback
import weakref
from collections.abc import Iterator
from pathlib import Path

from aeroexec.engine.catalog.descriptors import RECURRENT
from aeroexec.engine.errors import UNSUPPORTED, MissionAborted, RequestRejected, SpecificationError, unsupported_message
from aeroexec.engine.events import Outcome

from aeroexec import beliefs, drones

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.engine.execution.activation import ActivationConditions

#: The engine each mission thread talks to (one per thread: several engines fly side by side in one process).
_bound = threading.local()
#: Every engine bound now, by thread id: a thread of a mission's own that was never bound talks to the one
#: engine when exactly one is running (a single-drone mission's helper threads keep working).
_everywhere: dict[int, Any] = {}
_lock = threading.Lock()
_uids = itertools.count(1)
_activations: weakref.WeakValueDictionary[int, Any] = weakref.WeakValueDictionary()  # uid -> Activation
_uid_of: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()
#: Where aeroexec's own code lives: frames there are not the mission's.
_LIBRARY = tuple(str(Path(p).resolve().parent) + os.sep for p in (__file__, beliefs.__file__, drones.__file__))
RESERVED = ("timeout", "activation_delay", "activation_distance", "activation_yaw")

OK = "OK"
FAILED_PRECONDITIONS = Outcome.FAILED_PRECONDITIONS
GOAL_ACHIEVED = ACHIEVED_GOAL = Outcome.GOAL_ACHIEVED
TIME_OUT = Outcome.TIME_OUT
WRONG_PROGRESS = Outcome.WRONG_PROGRESS
INTERRUPTED = Outcome.INTERRUPTED


class Unification(dict):
    """Variable values by name as written (``'?X'``); ``'X'`` is accepted too, as Figure 10 reads them."""

    def __missing__(self, key: str) -> Any:
        if isinstance(key, str) and not key.startswith("?") and "?" + key in self:
            return self["?" + key]
        raise KeyError(key)


def bind(engine: Any) -> None:
    """Make ``engine`` the one the API talks to from this thread (done by the engine for its mission thread)."""
    _bound.engine = engine
    with _lock:
        _everywhere[threading.get_ident()] = engine


def unbind() -> None:
    """This thread talks to no engine any more."""
    _bound.engine = None
    with _lock:
        _everywhere.pop(threading.get_ident(), None)


@contextlib.contextmanager
def talking_to(engine: Any) -> Iterator[None]:
    """Within the block, this thread's API calls go to ``engine`` (a script that drives several drones)."""
    previous = getattr(_bound, "engine", None)
    _bound.engine = engine
    try:
        yield
    finally:
        _bound.engine = previous


def current_engine() -> Any:
    """The engine this thread's API calls go to (RuntimeError when none runs a mission here)."""
    return _engine()


def checked_request(name: str, **arguments: Any) -> tuple[str, dict[str, Any], dict[str, Any]]:
    """A behavior request checked as every API function checks it: the name, its catalog-cased arguments and
    the reserved options apart; :class:`RequestRejected` at the caller's line for what verify would refuse."""
    return _request(name, arguments)


def _engine() -> Any:
    engine = getattr(_bound, "engine", None)
    if engine is None:
        with _lock:
            running = {id(e): e for e in _everywhere.values()}
        if len(running) == 1:
            return next(iter(running.values()))
        if running:
            raise RuntimeError("this thread is bound to no engine and several engines run in this process: "
                               "call the mission API from the mission's own thread")
        raise RuntimeError("no engine is running this mission: run it with `aeroexec run MISSION.py`")
    return engine


def journaled(function: Any) -> Any:
    """A public call of the API: it goes through the engine's mission recorder when there is one (a journaled
    run records it, a resumed run replays it: ``engine/missions/replay.py``)."""
    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        recorder = _engine().bridge.recorder
        if recorder is None:
            return function(*args, **kwargs)
        return recorder.call(function, args, kwargs)

    return call


def _request(name: str, arguments: dict[str, Any]) -> tuple[str, dict[str, Any], dict[str, Any]]:
    """The behavior name and catalog-cased arguments, and the reserved options apart. Every request of a
    behavior goes through here: a request ``verify`` would have refused (unknown behavior, wrong argument or
    value, no implementation) raises :class:`RequestRejected` in the mission at the caller's line."""
    engine = _engine()
    name = str(name).upper()
    descriptor = engine.catalog.behavior(name)
    known = {}
    for argument in descriptor.arguments.values() if descriptor else ():
        known.update({alias.upper(): argument.name for alias in (argument.name, *argument.aliases)})
    options = {k: arguments.pop(k) for k in RESERVED if k in arguments}
    cased = {}
    for key, value in arguments.items():
        cased[known.get(key.upper(), key.upper())] = list_to_tuple(value)
    _check_request(engine, name, cased)
    return name, cased, options


def _check_request(engine: Any, name: str, arguments: dict[str, Any]) -> None:
    """Raise :class:`RequestRejected` (recorded as a ``rejected`` event) for a request the catalog or the
    behavior library refuses; the catalog is read-only while the engine runs, so this runs on the mission's
    thread."""
    try:
        engine.specialist.resolve_arguments(name, arguments)
    except SpecificationError as error:
        _reject(engine, name, error.kind, error.message)
    if name not in engine.library:  # implemented: its module is imported when the behavior is first activated
        _reject(engine, name, UNSUPPORTED, unsupported_message(name))


def _reject(engine: Any, name: str, kind: str, message: str) -> None:
    where = caller_location()
    engine.bridge.call(lambda: engine.log.record("rejected", name, message, error=kind, source="mission",
                                                 where=where))
    raise RequestRejected(kind, message, behavior=name, where=where)


def add_library_folder(folder: str | Path) -> None:
    """Frames of code under ``folder`` are not the mission's own (a mission API under other names lives there,
    such as Aerostack2's ``as2_python_api``): places in messages skip them."""
    global _LIBRARY
    path = str(Path(folder).resolve()) + os.sep
    if path not in _LIBRARY:
        _LIBRARY = (*_LIBRARY, path)


def caller_location() -> str:
    """``FILE:LINE`` of the innermost frame of the mission's own code on the current stack ("" if none)."""
    frames = [f for f in traceback.extract_stack()
              if not str(Path(f.filename).resolve()).startswith(_LIBRARY)]
    return f"{Path(frames[-1].filename).name}:{frames[-1].lineno}" if frames else ""


def list_to_tuple(value: Any) -> Any:
    """Points written as lists ``[2, 5, 1.3]`` are the catalog's tuples."""
    if isinstance(value, list | tuple):
        return tuple(list_to_tuple(v) for v in value)
    return value


def _conditions(options: dict[str, Any]) -> ActivationConditions | None:
    if not any(k.startswith("activation_") for k in options):
        return None
    from aeroexec.engine.execution.activation import ActivationConditions  # here: most requests have none

    point, distance = options.get("activation_distance", (None, None))
    yaw = options.get("activation_yaw")
    return ActivationConditions(tuple(point) if point is not None else None, distance,
                                options.get("activation_delay"), tuple(yaw) if yaw is not None else None)


def _run_behavior(name: str, arguments: dict[str, Any], started: list[bool] | None = None) -> tuple[Outcome, Any]:
    """Run a behavior to its end; ``started`` (when given) is told whether the activation was accepted."""
    name, args, options = _request(name, arguments)
    engine = _engine()
    descriptor = engine.catalog.behavior(name)
    if descriptor is not None and descriptor.category == RECURRENT and "timeout" not in options:
        raise ValueError(f"The behavior {name} is recurrent: it has no goal to wait for "
                         f"(use activate_behavior, or give timeout=)")

    def register(resolve: Any) -> None:
        result = engine.coordinator.activate(name, args, timeout=options.get("timeout"), source="mission",
                                             on_end=lambda outcome, message, value: resolve((outcome, value)))
        if started is not None:
            started.append(result.accepted)
        if not result.accepted:
            resolve((result.outcome or Outcome.FAILED_PRECONDITIONS, None))

    return engine.bridge.wait_for(register)


@journaled
def execute_behavior(name: str, **arguments: Any) -> Outcome:
    """Execute a goal-based behavior and wait until it ends: GOAL_ACHIEVED, TIME_OUT, WRONG_PROGRESS,
    FAILED_PRECONDITIONS or INTERRUPTED."""
    return _run_behavior(name, arguments)[0]


@journaled
def ask_behavior(name: str, **arguments: Any) -> Any:
    """Execute a deliberative behavior and return its result (None when it did not reach its goal)."""
    outcome, value = _run_behavior(name, arguments)
    return value if outcome is Outcome.GOAL_ACHIEVED else None


@journaled
def activate_behavior(name: str, **arguments: Any) -> str:
    """Activate a behavior and return at once: OK or FAILED_PRECONDITIONS."""
    name, args, options = _request(name, arguments)
    engine = _engine()
    conditions = _conditions(options)

    def activate() -> str:
        result = engine.coordinator.activate(name, args, timeout=options.get("timeout"), source="mission",
                                             conditions=conditions)
        return OK if result.accepted else str(Outcome.FAILED_PRECONDITIONS)

    return engine.bridge.call(activate)


@journaled
def inhibit_behavior(name: str) -> bool:
    """Stop a behavior (INTERRUPTED) and keep reactions from restarting it; always succeeds."""
    engine = _engine()
    engine.bridge.call(lambda: engine.coordinator.inhibit(str(name).upper(), "inhibited by the mission"))
    return True


@journaled
def run_behavior(name: str, **arguments: Any) -> tuple[bool, Outcome]:
    """Execute a behavior and wait until it ends: ``(True, outcome)``, or ``(False, why)`` when the activation
    itself was refused (Aerostack's ``executeTask`` convention)."""
    started: list[bool] = []
    outcome, _ = _run_behavior(name, arguments, started)
    return bool(started and started[0]), outcome


def task_failed(name: str, outcome: Any) -> None:
    """Say that a task the mission waited for ended without its goal (``outcome``: TIME_OUT, WRONG_PROGRESS), for
    APIs that hand the failure back as a value the mission may ignore (Aerostack's ``executeTask``): the run
    fails with it (``task_failed``, flight/run_status.py)."""
    engine = _engine()
    engine.bridge.call(lambda: engine.log.record("task_failed", name, f"{name} ended with {outcome}",
                                                 source="mission", outcome=str(outcome)))


@journaled
def start_behavior(name: str, **arguments: Any) -> tuple[bool, int]:
    """Activate a behavior and return at once: ``(accepted, uid)``; ``uid`` names this activation for
    :func:`stop_activation` (0 when refused)."""
    name, args, options = _request(name, arguments)
    engine = _engine()
    conditions = _conditions(options)

    def activate() -> tuple[bool, int]:
        result = engine.coordinator.activate(name, args, timeout=options.get("timeout"), source="mission",
                                             conditions=conditions)
        if not result.accepted or result.activation is None:
            return False, 0
        return True, _uid(result.activation)

    return engine.bridge.call(activate)


def _uid(activation: Any) -> int:
    with _lock:
        uid = _uid_of.get(activation)
        if uid is None:
            uid = _uid_of[activation] = next(_uids)
            _activations[uid] = activation
        return uid


@journaled
def stop_activation(uid: int) -> bool:
    """Stop the activation ``uid`` (from :func:`start_behavior`) as inhibit does; False when it is not active."""
    engine = _engine()
    with _lock:
        activation = _activations.get(uid) if isinstance(uid, int) and not isinstance(uid, bool) else None
    if activation is None:
        return False

    def stop() -> bool:
        if engine.coordinator.active().get(activation.name) is not activation:
            return False
        return engine.coordinator.inhibit(activation.name, "inhibited by the mission")

    return engine.bridge.call(stop)


@journaled
def stop_behavior(name: str) -> bool:
    """Inhibit a behavior by name: True when it was active and is now stopped, False otherwise."""
    engine = _engine()
    name = str(name).upper()
    return engine.bridge.call(lambda: engine.coordinator.inhibit(name, "inhibited by the mission"))


@journaled
def is_active_behavior(name: str) -> bool:
    engine = _engine()
    return engine.bridge.call(lambda: engine.coordinator.is_active(str(name).upper()))


@journaled
def consult_belief(expression: str) -> tuple[bool, Unification]:
    """``(success, unification)`` of the first match of a belief expression."""
    engine = _engine()
    success, unification = engine.bridge.call(lambda: engine.memory.consult(expression))
    return success, Unification(unification)


@journaled
def true_belief(expression: str) -> bool:
    engine = _engine()
    return engine.bridge.call(lambda: engine.memory.holds(expression))


@journaled
def add_belief(belief: str, multivalued: bool = False) -> bool:
    """Add a belief; a predicate nobody declared is declared by the mission (``multivalued`` or exclusive)."""
    engine = _engine()

    def add() -> bool:
        term = beliefs.parse_belief(belief) if isinstance(belief, str) else belief
        if not engine.memory.accepts(term.name):
            engine.memory.declare(term.name, len(term.args), multivalued=multivalued)
        return engine.memory.add(term)

    return engine.bridge.call(add)


@journaled
def remove_belief(pattern: str) -> int:
    engine = _engine()
    return engine.bridge.call(lambda: engine.memory.remove(pattern))


def add_rules(rules: str) -> list[beliefs.Rule]:
    """Add rules deriving beliefs (and facts): ``safe_zone(?Z) :- zone(?Z), not(occupied(?Z)).`` Derived
    predicates are then asked like stored ones. Raises :class:`~aeroexec.beliefs.RuleError` naming the mission's
    file and the line of each mistake. (Not journaled: a resumed mission adds its rules again as it replays.)"""
    engine = _engine()
    caller = sys._getframe(1)
    where, line = Path(caller.f_code.co_filename).name, caller.f_lineno
    return engine.bridge.call(lambda: engine.memory.add_rules(rules, where, line))


@journaled
def why(expression: str) -> str:
    """Why a belief expression holds: the proof of its first answer, one line per rule or belief used (indented
    under what it proves); empty when it does not hold."""
    engine = _engine()

    def proof() -> str:
        found = engine.memory.why(expression)
        return "\n".join(str(p) for p in found) if found else ""

    return engine.bridge.call(proof)


@journaled
def why_not(expression: str) -> str:
    """Why a belief expression does not hold: the goal that fails (through the rules of a derived one) and what
    the memory holds for it; empty when it holds."""
    engine = _engine()
    return engine.bridge.call(lambda: "\n".join(engine.memory.why_not(expression)))


@journaled
def wait(seconds: float) -> None:
    """Let ``seconds`` of engine time pass (use this, not ``time.sleep``, so simulated time is respected)."""
    engine = _engine()
    if seconds < 0:
        raise ValueError(f"cannot wait {seconds} seconds")

    def register(resolve: Any) -> None:
        engine.timers.after(seconds, lambda: resolve(None))

    engine.bridge.wait_for(register)


@journaled
def now() -> float:
    """The engine's clock, in seconds since it started (a call like any other: polling it lets time move)."""
    engine = _engine()
    return engine.bridge.call(engine.now)


def mission_location(exc: BaseException) -> str:
    """`` at FILE:LINE``: the last place in the mission's own code that the exception went through."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__)
              if not str(Path(f.filename).resolve()).startswith(_LIBRARY)]
    if not frames:
        return ""
    frame = frames[-1]
    return f" at {Path(frame.filename).name}:{frame.lineno}"


# The paper's (Table 8) and Aerostack's spellings.
executeBehavior = execute_behavior
activateBehavior = activate_behavior
askBehavior = ask_behavior
inhibitBehavior = inhibit_behavior
deactivateBehavior = inhibit_behavior
isActiveBehavior = is_active_behavior
consultBelief = consult_belief
queryBelief = consult_belief
trueBelief = true_belief
addBelief = add_belief
removeBelief = remove_belief
executeTask = execute_behavior
startTask = activate_behavior
stopTask = inhibit_behavior

__all__ = [
    "MissionAborted", "RequestRejected", "Unification", "activate_behavior", "add_belief", "add_rules", "ask_behavior",
    "consult_belief", "execute_behavior", "inhibit_behavior", "is_active_behavior", "now", "remove_belief",
    "run_behavior", "start_behavior", "stop_activation", "stop_behavior", "task_failed", "true_belief", "wait", "why",
    "why_not",
]
