"""A Python mission's API calls, journaled as they are made, and replayed to resume an interrupted run: deterministic
replay, as durable-execution engines (Temporal, DBOS) resume a workflow.

A :class:`MissionRecorder` stands between the mission and the API (``engine.bridge.recorder``; the API's public
functions go through it when it is set). Live, each call runs and is told to a :class:`CallJournal`: a call that
waits (``execute_behavior``, ``ask_behavior``, ``run_behavior``, ``wait``) when it is made and again when it
returns; any other call when it returns. Resuming, the mission runs again from the top and the recorder answers
each call the journal has a result for with that result at once, without acting, after checking that it is the
same call (the same function with the same arguments; its line may differ): a mission whose calls differ raises
:class:`MissionDiverged` at the call where it diverged, naming its line and the interrupted run's call, and every
call after that raises it again. The first call the journal has no result for is made live: ``on_live`` is run
first (the flight puts the drone back where the mission left it), then the mission goes on live. A ``wait`` that
was under way waits only what was left of it.
"""

from __future__ import annotations

import builtins
import functools
import json
import sys
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from aeroexec.engine import api
from aeroexec.engine.errors import MissionAborted, RequestRejected
from aeroexec.engine.missions.values import call_text, decode, text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, Protocol
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

#: The calls that wait for the engine (a behavior to end, time to pass).
WAITING = frozenset({"execute_behavior", "ask_behavior", "run_behavior", "wait"})


class MissionDiverged(RequestRejected):
    """A resumed mission made a call the interrupted run did not make there (another behavior, other arguments,
    another order, or it ended early): it is refused at that call."""

    def __init__(self, message: str, where: str) -> None:
        super().__init__("DIVERGED", message, where=where)

    def __str__(self) -> str:
        return self.message


@dataclass(frozen=True)
class RecordedCall:
    """A call of the interrupted run: its number in the mission (from 1), function, arguments (``canonical`` text
    of the encoded ``[args, kwargs]``), place, and what it returned or raised (encoded), when it did."""

    number: int
    function: str
    arguments: str
    location: str
    requested_at: float = 0.0
    returned: bool = True
    result: Any = None  # encoded
    error: dict[str, Any] | None = None  # {"type", "message", "kind", "behavior", "where"}

    def answer(self) -> Any:
        """The recorded result (decoded), or the recorded exception raised."""
        if self.error is not None:
            raise _rebuilt(self.error)
        return decode(self.result)

    def shown(self) -> str:
        """The call as the mission wrote it, roughly: ``execute_behavior('GO_TO_POINT', point=(2, 5, 1.3))``."""
        return shown(self.function, decode(_loads(self.arguments)))


class CallJournal(Protocol):
    """Where a recorder tells the calls (the flight journal)."""

    def call_requested(self, number: int, function: str, arguments: str, location: str, time: float) -> None: ...

    def call_returned(self, number: int, function: str, arguments: str, location: str, time: float,
                      result: str | None, error: dict[str, Any] | None) -> None:
        """``result``: the value returned, as text (``values.text``); None with ``error``."""


class MissionRecorder:
    """Records a mission's calls to ``journal`` and replays ``replay`` (the interrupted run's completed calls, in
    order, numbered from 1) before going live. ``pending``: the call that was under way when the run stopped (made
    live again after the replay, checked first). ``on_live`` runs once, on the mission's thread, before the first
    live call of a resumed mission (it may raise to refuse going on, or answer the call under way, settled
    meanwhile, with ``(value,)``); ``now`` is the engine's clock."""

    def __init__(self, journal: CallJournal | None, now: Callable[[], float], *,
                 replay: Sequence[RecordedCall] = (), pending: RecordedCall | None = None,
                 on_live: Callable[[], tuple[Any] | None] | None = None) -> None:
        self.journal, self.now = journal, now
        self.replay = list(replay)
        self.pending = pending
        self.on_live = on_live
        self.count = 0  # calls made so far
        self.live = not self.replay and pending is None
        self.diverged: MissionDiverged | None = None
        self._lock = threading.Lock()

    @property
    def replaying(self) -> bool:
        return not self.live

    def call(self, function: Callable[..., Any], args: tuple, kwargs: dict[str, Any]) -> Any:
        """Make (or replay) one call of the mission API."""
        name = function.__name__
        if self.diverged is not None:
            raise self.diverged
        with self._lock:
            self.count += 1
            number = self.count
        if self.live:
            return self._live(function, name, args, kwargs, number)
        arguments = call_text(args, kwargs)
        if not self.live:
            recorded = self.replay[number - 1] if number <= len(self.replay) else self.pending
            if recorded is not None and recorded.number == number:
                self._check(recorded, name, arguments)
                if recorded is not self.pending:
                    return recorded.answer()
                if name == "wait" and args:  # it was under way: only what is left of it
                    args = (max(0.0, recorded.requested_at + float(args[0]) - self.now()),)
            answer = self._go_live()
            if answer is not None:  # the call under way reached its goal while the mission went live
                if self.journal is not None:
                    self.journal.call_returned(number, name, arguments, location(), self.now(), text(answer[0]), None)
                return answer[0]
        return self._live(function, name, args, kwargs, number, arguments)

    def wrap(self, mission: Callable[[], Any]) -> Callable[[], Any]:
        """``mission``, refused at its end (:meth:`finish`) when it ends before the calls it made before."""
        @functools.wraps(mission)
        def journaled() -> Any:
            result = mission()
            self.finish()
            return result

        return journaled

    def finish(self) -> None:
        """The mission's function returned: refuse it when it ended before the calls the interrupted run made."""
        if self.diverged is not None:
            raise self.diverged
        if self.live:
            return
        recorded = self.replay[self.count] if self.count < len(self.replay) else self.pending
        if recorded is None:  # every call was replayed: the mission went on to its end (it was about to)
            self._go_live()
            return
        self.diverged = MissionDiverged(
            f"the mission ended after {self.count} calls, where the interrupted run went on with "
            f"{recorded.shown()} ({recorded.location}): it is not the mission that was interrupted",
            where=recorded.location)
        raise self.diverged

    # -- inside -------------------------------------------------------------------------------------------
    def _check(self, recorded: RecordedCall, name: str, arguments: str) -> None:
        if (recorded.function, recorded.arguments) == (name, arguments):
            return
        where = location()
        self.diverged = MissionDiverged(
            f"{where}: the mission differs from the interrupted run at its call {recorded.number}: it calls "
            f"{shown(name, decode(_loads(arguments)))} where the interrupted run called {recorded.shown()} "
            f"({recorded.location}); resume with the mission as it was, or run the new one from the start",
            where=where)
        raise self.diverged

    def _go_live(self) -> tuple[Any] | None:
        self.live = True
        return self.on_live() if self.on_live is not None else None

    def _live(self, function: Callable[..., Any], name: str, args: tuple, kwargs: dict[str, Any], number: int,
              arguments: str | None = None) -> Any:
        journal = self.journal
        if journal is None:
            return function(*args, **kwargs)
        if arguments is None:
            arguments = call_text(args, kwargs)
        where = location(_MISSION_DEPTH)
        if name in WAITING:
            journal.call_requested(number, name, arguments, where, self.now())
        try:
            result = function(*args, **kwargs)
        except MissionAborted:
            raise  # the run is ending: the call has no result
        except Exception as error:
            journal.call_returned(number, name, arguments, where, self.now(), None, _error(error))
            raise
        journal.call_returned(number, name, arguments, where, self.now(), text(result), None)
        return result


def location(skip: int = 0) -> str:
    """``FILE:LINE`` of the innermost frame of the mission's own code (not aeroexec's) on this thread's stack, the
    ``skip`` frames above the caller's (known to be aeroexec's) left out."""
    depth = 1 + skip
    while True:  # frame by frame from the inside: only the frames looked at are made (f_back would make them all)
        try:
            frame = sys._getframe(depth)
        except ValueError:  # the stack's end
            return ""
        name = _mission_file(frame.f_code.co_filename)
        if name is not None:
            return f"{name}:{frame.f_lineno}"
        depth += 1


#: The frames above a live call's recording that are aeroexec's: the recorder's (``_live``, ``call``) and the
#: API's wrapper (``api.journaled``).
_MISSION_DEPTH = 3


@functools.lru_cache(maxsize=256)
def _mission_file(filename: str) -> str | None:
    """The file's name when it is the mission's (not aeroexec's own code), else None."""
    if filename.startswith(api._LIBRARY) or str(Path(filename).resolve()).startswith(api._LIBRARY):
        return None
    return Path(filename).name


def shown(function: str, arguments: Any) -> str:
    """A call as text: ``function('A', key=value)``."""
    args, kwargs = (arguments if isinstance(arguments, list) and len(arguments) == 2 else ([], {}))
    parts = [repr(a) for a in args] + [f"{k}={v!r}" for k, v in dict(kwargs).items()]
    return f"{function}({', '.join(parts)})"


def _loads(text: str) -> Any:
    return json.loads(text)


def _error(error: Exception) -> dict[str, Any]:
    return {"type": type(error).__name__, "message": str(getattr(error, "message", error)),
            "kind": getattr(error, "kind", ""), "behavior": getattr(error, "behavior", ""),
            "where": getattr(error, "where", "")}


def _rebuilt(error: dict[str, Any]) -> Exception:
    """The exception a call raised, made again (RequestRejected as it was; others as a RuntimeError-like of the
    same name and message)."""
    if error.get("type") == "RequestRejected":
        return RequestRejected(error.get("kind", ""), error.get("message", ""), behavior=error.get("behavior", ""),
                               where=error.get("where", ""))
    cls = getattr(builtins, str(error.get("type", "")), None)
    if isinstance(cls, type) and issubclass(cls, Exception):
        try:
            return cls(error.get("message", ""))
        except Exception:  # an exception class that needs other arguments
            pass
    return RuntimeError(f"{error.get('type', 'Error')}: {error.get('message', '')}")


__all__ = ["WAITING", "CallJournal", "MissionDiverged", "MissionRecorder", "RecordedCall", "location", "shown"]
