"""One simulation case flown in this process on the simulated clock, as ``aeroexec run`` flies it: a
:class:`~aeroexec.flight.session.FlightSession`, the operator's commands submitted to its supervisor at their
simulated times (the control socket's path), faults injected at theirs; ``kill -9`` is the session abandoned as a
killed process leaves its files (the journal keeps what it committed, the logs stop where they are), then a new
session resumes the run from its folder (``--resume``). What the flight left is a :class:`Flown`, which the
invariants judge.

Each engine step is timed in CPU seconds of the loop's thread (a loaded machine does not lengthen it).
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import random
import resource
import shlex
import shutil
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from aeroexec.rehearsal.simulation.cases import RUNNING, Action, Case, Fault, drawn_kinds
from aeroexec.rehearsal.simulation.missions import draw_mission

logger = logging.getLogger(__name__)

SLOW_WRITE = 0.002  # s each write of the event log takes on a slow disk


class Killed(BaseException):
    """``kill -9`` at this point of the flight: nothing of the process runs after it (not a KeyboardInterrupt)."""


@dataclass
class Part:
    """One process's part of the run: how it ended and what it measured."""

    refused: str | None = None  # the set-up refused the flight (FlightError), with its message
    crashed: bool = False  # killed (kill -9) before its end
    outcome: Any = None  # its FlightOutcome
    error: str | None = None  # an exception no one caught (an internal error)
    longest_step: float = 0.0  # CPU s of the loop's thread
    longest_at: float = 0.0  # when (engine time)
    steps: int = 0
    armed: bool = False
    altitude: float = 0.0
    landed_state: str = ""  # as the autopilot reports it (on_ground: landed, on the ground or on a deck)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    link_ok: bool = True
    crashed_drone: str | None = None  # the vehicle crashed (the simulator says why)
    state_known: bool = True  # the drone's last state is known (not for a process whose event log stopped short)
    answers: list[tuple[str, bool, str]] = field(default_factory=list)  # (command, ok, message)


@dataclass
class Flown:
    """What one case left: its parts (two after kill -9 and --resume), the run's folder, the errors logged, the
    points the mission may fly to, and the process's peak memory."""

    case: Case
    folder: Path
    parts: list[Part] = field(default_factory=list)
    logged: list[str] = field(default_factory=list)  # ERROR records of aeroexec's loggers
    allowed_points: set[tuple[float, ...]] = field(default_factory=set)
    peak_memory: float = 0.0  # MB, the process's
    wall: float = 0.0
    cpu: float = 0.0
    exit_status: int | None = None  # a real process's
    last_line: str = ""  # a real process's last line of stderr


class _Errors(logging.Handler):
    """The ERROR records of aeroexec's loggers while a case flies."""

    def __init__(self) -> None:
        super().__init__(logging.ERROR)
        self.found: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        if record.exc_info or "please report it" in text:
            kind = record.exc_info[0].__name__ if record.exc_info and record.exc_info[0] else ""
            self.found.append(f"{record.name}: {text}{f' ({kind}: {record.exc_info[1]})' if kind else ''}")


@contextlib.contextmanager
def _errors_logged() -> Iterator[_Errors]:
    handler = _Errors()
    root = logging.getLogger("aeroexec")
    root.addHandler(handler)
    try:
        yield handler
    finally:
        root.removeHandler(handler)


class _Disk:
    """``os`` for the event log's writer: full after ``room`` bytes (ENOSPC, the write crossing it cut short), or
    slow (each write takes :data:`SLOW_WRITE`)."""

    def __init__(self, room: int | None, slow: bool) -> None:
        self.room, self.slow = room, slow

    def __getattr__(self, name: str) -> Any:
        return getattr(os, name)

    def write(self, fd: int, data: bytes) -> int:
        if self.slow:
            time.sleep(SLOW_WRITE)
        if self.room is None:
            return os.write(fd, data)
        if self.room <= 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        part = bytes(data[:self.room])
        self.room -= len(part)
        return os.write(fd, part)


@contextlib.contextmanager
def _disk(fault: Fault | None) -> Iterator[None]:
    from aeroexec.flight import flight_log

    if fault is None:
        yield
        return
    real = flight_log.os
    flight_log.os = _Disk(fault.size if fault.kind == "disk_full" else None, fault.kind == "slow_disk")
    try:
        yield
    finally:
        flight_log.os = real


class _FullPhoto:
    """Where a photo would go on a full disk: writing it fails with ENOSPC."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def write_bytes(self, data: bytes) -> int:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self.path))

    def unlink(self, missing_ok: bool = False) -> None:
        """What was written of it is removed (nothing was)."""
        self.path.unlink(missing_ok=missing_ok)

    def __str__(self) -> str:
        return str(self.path)


@contextlib.contextmanager
def _photos(fault: Fault | None) -> Iterator[None]:
    """Photos written until ``fault.size`` of them were, then ENOSPC."""
    from aeroexec.engine.behaviors import recording

    if fault is None:
        yield
        return
    real, written = recording.next_path, [0]

    def next_path(*args: Any, **kwargs: Any) -> Any:
        path = real(*args, **kwargs)
        written[0] += 1
        return path if written[0] <= fault.size else _FullPhoto(path)

    recording.next_path = next_path
    try:
        yield
    finally:
        recording.next_path = real


class _Operator:
    """A tick callback: each action at its simulated time, submitted to the supervisor as the control socket does
    (their answers kept); each fault of the loop (kill -9, SIGTERM, SIGHUP) raised at its time."""

    def __init__(self, engine: Any, actions: list[Action], faults: list[Fault], part: Part,
                 mission_done: Any = lambda: False, after_end: bool = False) -> None:
        self.engine, self.actions, self.faults, self.part = engine, actions, faults, part
        self.mission_done, self.after_end = mission_done, after_end
        self.tickets: list[tuple[Action, Any]] = []

    def __call__(self) -> None:
        now = self.engine.now()
        while self.actions and self.actions[0].time <= now:
            action = self.actions.pop(0)
            if RUNNING in action.argument:
                action = self._at_running(action)
            try:
                ticket = self.engine.supervisor.submit(action.command, action.argument, "ctl")
            except Exception as error:  # noqa: BLE001 - the control socket would log it and close with no answer
                self.part.answers.append((str(action), False, f"submit raised {type(error).__name__}: {error}; "
                                                              f"the connection closes unanswered: please report it"))
                continue
            self.tickets.append((action, ticket))
        while self.faults and self.faults[0].time <= now:
            fault = self.faults.pop(0)
            if fault.kind in ("crash", "edited_resume", "foreign_journal"):
                if self.mission_done() and not self.after_end:  # the flight is ending: see FOUND crash_after_end
                    continue
                raise Killed(fault.kind)
            from aeroexec.flight.signals import Interrupted

            raise Interrupted(fault.kind.upper())

    def _at_running(self, action: Action) -> Action:
        """The edit's target: the item running now, as ``ctl items`` says (the end's, when none runs)."""
        listed = self.engine.supervisor.execute("items", origin="ctl")
        items = listed.data.get("items", []) if listed.ok else []
        running = [item for item in items if item.get("status") == "running"]
        chosen = running[-1] if running else items[-1] if items else {"item": 1}
        return replace(action, argument=action.argument.replace(RUNNING, str(chosen.get("item", 1))))

    def answers(self) -> list[tuple[str, bool, str]]:
        found = []
        for action, ticket in self.tickets:
            result = ticket.result
            found.append((str(action), bool(result and result.ok), result.message if result else "not run"))
        return found


def _timed(engine: Any, part: Part) -> None:
    """Each engine step timed in CPU seconds of the loop's thread."""
    tick = engine.tick

    def timed() -> None:
        began = time.thread_time()
        try:
            tick()
        finally:
            took = time.thread_time() - began
            part.steps += 1
            if took > part.longest_step:
                part.longest_step, part.longest_at = took, engine.now()

    engine.tick = timed


def _abandon(session: Any) -> None:
    """End a session as ``kill -9`` leaves a run: the journal keeps what it committed, the logs stop where they
    are (no run_ended, no log_closed)."""
    if session.journal is not None:
        session.journal.abandon()
    for writer in (session.flight_log, session.btlog):
        fd = getattr(writer, "_fd", None)
        if fd is not None:
            writer._fd = None
            os.close(fd)
    session.journal = session.flight_log = session.btlog = None
    session.close()


def _drone_state(session: Any, part: Part) -> None:
    robot = session.robot
    if robot is None:
        return
    telemetry = robot.telemetry()
    part.armed, part.position = telemetry.armed, tuple(telemetry.position)
    part.altitude = telemetry.position[2]
    part.landed_state = getattr(telemetry.landed_state, "value", str(telemetry.landed_state))
    link = getattr(robot, "link_ok", None)
    part.link_ok = link(session.engine.now()) if callable(link) and session.engine is not None else True
    part.crashed_drone = getattr(robot, "crashed", None)


def fly_part(case: Case, spec: Any, actions: list[Action], faults: list[Fault], robot: Any = None,
             world: Any = None, extra: frozenset[str] = frozenset()) -> tuple[Part, Any]:
    """One process's part of the run: set up, fly, end (or be killed); the part and its session."""
    from aeroexec.flight.session import FlightSession
    from aeroexec.flight.spec import FlightError

    part = Part()
    session = FlightSession(spec, notify=lambda text: None, report=lambda problem: None, robot=robot, world=world)
    try:
        session.open()
    except FlightError as error:
        part.refused = str(error)
        return part, session
    except Exception as error:  # noqa: BLE001 - the set-up raised what it should have said: an internal error
        part.error = f"the set-up raised {type(error).__name__}: {error}"
        session.close()
        return part, session
    _timed(session.engine, part)
    operator = _Operator(session.engine, actions, faults, part, lambda: session.mission_done,
                         "crash_after_end" in extra)
    session.engine.tick_callbacks.append(operator)
    try:
        part.outcome = session.fly()
    except Killed:
        part.crashed = True
        _drone_state(session, part)
        _abandon(session)
    except Exception as error:  # noqa: BLE001
        part.error = f"the flight raised {type(error).__name__}: {error}"
        session.close()
    else:
        _drone_state(session, part)
    part.answers += operator.answers()
    return part, session


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


def _load_argument(case: Case, scratch: Path, action: Action, allowed: set[tuple[float, ...]]) -> Action:
    """``ctl load``'s new mission, drawn from the case's seed and written beside the first."""
    if action.command != "load":
        return action
    mission = draw_mission(random.Random(case.seed * 7919 + int(action.time * 100)), ("tree", "python"),
                           airborne=True)
    allowed.update(mission.points)
    path = _write(scratch, f"loaded{mission.suffix}", mission.text)
    return replace(action, argument=shlex.quote(str(path)))


def _edit_points(action: Action) -> set[tuple[float, ...]]:
    found = set()
    if "COORDINATES=" in action.argument:
        text = action.argument.split("COORDINATES=", 1)[1].strip("'\" ")
        with contextlib.suppress(ValueError):
            found.add(tuple(round(float(v), 1) for v in text.strip("\"'").split(",")))
    return found


def fly_case(case: Case, scratch: Path, extra: frozenset[str] = frozenset()) -> Flown:
    """Fly ``case`` with its files in ``scratch`` (its run folder: ``scratch/run``); ``extra``: the gated kinds
    asked for (:data:`~aeroexec.rehearsal.simulation.cases.GATED`; those of ``FOUND`` are always drawn)."""
    extra = drawn_kinds(extra)
    from aeroexec.drones.sim import SimulatedDrone
    from aeroexec.drones.sim.config import SimConfig
    from aeroexec.flight.journal import resume_spec
    from aeroexec.flight.robot import load_world
    from aeroexec.flight.spec import FlightSpec

    began, cpu = time.perf_counter(), time.process_time()
    folder = scratch / "run"
    flown = Flown(case, folder)
    mission_path = _write(scratch, f"mission{case.mission.suffix}", case.mission.text)
    flown.allowed_points.update(tuple(round(v, 1) for v in p) for p in case.mission.points)
    rules = (str(_write(scratch, "rules.txt", case.rules)),) if case.rules else ()
    safety = (str(_write(scratch, "safety.yaml", case.safety_rules)),) if case.safety_rules else ()
    actions = [_load_argument(case, scratch, a, flown.allowed_points) for a in case.actions]
    for action in actions:
        flown.allowed_points |= _edit_points(action)
    horizon = 60.0 + 10.0 * case.mission.leaves
    spec = FlightSpec(mission=mission_path, output=str(folder), register=False, seed=case.seed, max_time=horizon,
                      rules=rules, safety_rules=safety, link_grace=10.0)
    loop_faults = sorted((f for f in case.faults if f.kind in ("crash", "sigterm", "sighup", "edited_resume",
                                                               "foreign_journal")), key=lambda f: f.time)
    disk = next((f for f in case.faults if f.kind in ("disk_full", "slow_disk")), None)
    drop = case.fault("link_drop")
    robot = world = None
    if drop is not None:
        world = load_world(None, default=True, mission=mission_path)
        robot = SimulatedDrone(world, config=SimConfig(link_loss=(drop.time, drop.length)), seed=case.seed)
    with _errors_logged() as errors, _disk(disk), _photos(case.fault("photo_enospc")):
        remaining = list(actions)
        part, session = fly_part(case, spec, remaining, list(loop_faults[:1]), robot, world, extra)
        flown.parts.append(part)
        if part.crashed:
            killed = loop_faults[0]
            if killed.kind == "edited_resume":  # every point of the mission 1.5 m further east after the crash
                text = case.mission.text
                for x, y, z in case.mission.points:
                    text = text.replace(f'"{x}, {y}, {z}"', f'"{round(x + 1.5, 1)}, {y}, {z}"')
                mission_path.write_text(text)
            elif killed.kind == "foreign_journal":  # another run's journal copied into this folder
                other = scratch / "other"
                other.mkdir()
                other_mission = _write(other, "mission.xml", draw_mission(random.Random(case.seed + 1),
                                                                          ("tree",)).text)
                other_spec = replace(spec, mission=other_mission, output=str(other / "run"))
                fly_part(case, other_spec, [], [Fault("crash", 3.0)])
                for name in os.listdir(other / "run"):
                    if name.startswith("journal.sqlite"):
                        shutil.copy(other / "run" / name, folder / name)
            try:
                again = replace(resume_spec(folder), register=False, max_time=horizon, link_grace=10.0)
            except Exception as error:  # noqa: BLE001 - JournalError: refused; anything else is a bug
                from aeroexec.flight.journal import JournalError

                resumed = Part(refused=str(error)) if isinstance(error, JournalError) else Part(
                    error=f"resume_spec raised {type(error).__name__}: {error}")
            else:
                resumed, _ = fly_part(case, again, list(remaining), list(loop_faults[1:]), extra=extra)
            flown.parts.append(resumed)
        flown.logged = list(errors.found)
    flown.peak_memory = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    flown.wall, flown.cpu = time.perf_counter() - began, time.process_time() - cpu
    return flown


__all__ = ["Flown", "Killed", "Part", "fly_case", "fly_part"]
