"""What every motion behavior shares: drone commands tracked without blocking, health checks (link, refused or
unanswered commands, still flying), a watch for lack of progress, holding on any non-goal end, and ENU geometry.

A motion behavior extends :class:`MotionBehavior` and writes ``begin(telemetry)`` (send the first commands
through :meth:`MotionBehavior.command`) and ``step(telemetry)`` (one tick of monitoring); the base class
turns a refused command, a command not accepted in time, a lost link or a drone that fell out of the sky
into WRONG_PROGRESS with a reason the operator can read.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from typing import Any, ClassVar

from aeroexec.drones import CommandHandle, Failure, LandedState, Telemetry, Vector
from aeroexec.drones.angles import wrap180
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess, Situation

logger = logging.getLogger(__name__)

ARRIVAL_SPEED = 0.5  # m/s: a point is reached once within tolerance and slower than this
PROGRESS_STEP = 0.05  # m: a distance must shrink by this much to count as progress
YAW_PROGRESS_STEP = 1.0  # degrees: the same for a heading error
# Drone events that explain why it is down, most telling first, with how to introduce their detail.
_DOWN_EVENTS = {"drone_collision": "", "drone_battery_empty": "", "drone_failsafe": "failsafe: ",
                "drone_disarmed": "disarmed: ", "drone_landed": "it landed "}

# Directions relative to the heading, in degrees counterclockwise (KEEP_MOVING and FLIP name them differently).
RELATIVE_HEADINGS = {"FORWARD": 0.0, "FRONT": 0.0, "LEFT": 90.0, "BACKWARD": 180.0, "BACK": 180.0,
                     "RIGHT": -90.0}


# -- geometry ---------------------------------------------------------------------------------------------


def yaw_error(yaw: float, target: float) -> float:
    """How many degrees ``yaw`` is off ``target``, the short way round."""
    return abs(wrap180(target - yaw))


def heading_to(origin: Sequence[float], target: Sequence[float]) -> float | None:
    """The ENU yaw (degrees) from ``origin`` to ``target`` in the horizontal plane; None right above or below."""
    dx, dy = target[0] - origin[0], target[1] - origin[1]
    if math.hypot(dx, dy) < 1e-6:
        return None
    return math.degrees(math.atan2(dy, dx))


def as_point(value: Sequence[Any]) -> Vector:
    """A point argument (list or tuple of three numbers) as a tuple of floats."""
    x, y, z = (float(v) for v in value)
    return (x, y, z)


def offset(point: Sequence[float], delta: Sequence[float]) -> Vector:
    return as_point(p + d for p, d in zip(point, delta, strict=True))


def horizontal_unit(yaw: float) -> Vector:
    """The horizontal unit vector a heading of ``yaw`` degrees points along."""
    rad = math.radians(yaw)
    return (math.cos(rad), math.sin(rad), 0.0)


def fmt_point(point: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.1f}" for v in point) + ")"


# -- progress ----------------------------------------------------------------------------------------------
class ProgressWatch:
    """Notices ``stall_time`` seconds without progress: none of the watched errors shrank by its step."""

    def __init__(self, stall_time: float, now: float, steps: Sequence[float] = (PROGRESS_STEP,)) -> None:
        self.stall_time = stall_time
        self.steps = tuple(steps)
        self.reset(now)

    def reset(self, now: float) -> None:
        """Start watching afresh (a new leg, a new phase)."""
        self.best = [math.inf] * len(self.steps)
        self.since = now

    def stalled(self, now: float, *errors: float) -> bool:
        """Record the current errors; True once no error has improved for ``stall_time`` seconds."""
        best, steps = self.best, self.steps
        if len(errors) != len(steps):
            raise ValueError(f"{len(errors)} errors watched with {len(steps)} progress steps")
        for i in range(len(steps)):  # (every period of a motion behavior: no zip, no enumerate)
            error, was = errors[i], best[i]
            if error <= was - steps[i] or was == math.inf or was == -math.inf:  # math.isinf, without its call
                best[i] = error
                self.since = now
        return now - self.since >= self.stall_time


# -- the base class ----------------------------------------------------------------------------------------
class MotionBehavior(BehaviorProcess):
    """A behavior that moves the drone: commands without blocking, health checks, hold on a non-goal end."""

    #: The drone must stay in the air while the behavior runs (False for TAKE_OFF and LAND).
    needs_flight: ClassVar[bool] = True
    #: The steps :attr:`progress` counts as progress, one per error passed to :meth:`no_progress`.
    progress_steps: ClassVar[tuple[float, ...]] = (PROGRESS_STEP,)

    # -- hooks for subclasses -------------------------------------------------------------------------
    def begin(self, telemetry: Telemetry) -> None:
        """Send the first commands (through :meth:`command`)."""

    def step(self, telemetry: Telemetry) -> Outcome | None:
        """One tick once the common checks passed: GOAL_ACHIEVED, WRONG_PROGRESS (:meth:`fail`) or None."""
        return None

    # -- the process hooks ------------------------------------------------------------------------------
    def check_situation(self) -> Situation | None:
        if not self.needs_flight:
            return None
        t = self.telemetry()
        if not t.link_ok:
            return Situation(Outcome.FAILED_PRECONDITIONS, "The link to the drone is lost.")
        if not t.armed:
            return Situation(Outcome.FAILED_PRECONDITIONS, "The drone's motors are not armed.")
        return None

    def on_start(self) -> None:
        self._commands: list[tuple[CommandHandle, float]] = []
        self.progress = ProgressWatch(self.settings.stall_time, self.now(), self.progress_steps)
        t = self.telemetry()
        self._was_armed = t.armed
        self._answered = False  # the drone has accepted a command: progress is watched from then on
        self.begin(t)

    def on_run(self) -> Outcome | None:
        t = self.context.drone.telemetry()  # self.telemetry(), one call fewer (every period)
        if not t.link_ok:
            return self.fail("the link to the drone is lost")
        armed = t.armed
        self._was_armed = self._was_armed or armed
        # the common checks, each called only when it may find trouble: no command waiting for its answer once one
        # was accepted leaves _command_trouble nothing to do, and a drone armed in the air none to _flight_trouble
        if self._commands or not self._answered:
            trouble = self._command_trouble()
            if trouble:
                return self.fail(trouble)
        if not armed or t.landed_state is not LandedState.IN_AIR:
            trouble = self._flight_trouble(t)
            if trouble:
                return self.fail(trouble)
        return self.step(t)

    def on_stop(self, outcome: Outcome) -> None:
        if outcome is not Outcome.GOAL_ACHIEVED:
            self.hold()

    # -- helpers for subclasses ---------------------------------------------------------------------------
    def command(self, handle: CommandHandle) -> CommandHandle:
        """Track a command: its refusal, or no answer within ``command_timeout``, ends the behavior."""
        self._commands.append((handle, self.now()))
        return handle

    def hold(self) -> None:
        """Stop and hover where the drone is (when it flies); never waits for the answer."""
        t = self.telemetry()
        if not t.armed or t.landed_state is LandedState.ON_GROUND:
            return
        handle = self.drone.hold()
        if handle.done and not handle.ok:
            logger.warning("%s: could not hold the drone: %s", self.name, handle.reason)

    def no_progress(self, what: str | Callable[[], str], *errors: float) -> Outcome | None:
        """WRONG_PROGRESS when none of ``errors`` shrank for ``stall_time``; ``what`` completes the reason (a function
        giving it, on the hot path: the text is made only when someone will read it)."""
        if self.progress.stalled(self.context.clock(), *errors):  # (self.now(), one call fewer: every period)
            return self.fail(f"no progress {what() if callable(what) else what} for {self.settings.stall_time:g} s")
        return None

    def arrived(self, telemetry: Telemetry, point: Sequence[float]) -> bool:
        """Within the position tolerance of ``point`` and nearly still."""
        return (math.dist(telemetry.position, point) <= self.context.settings.position_tolerance
                and telemetry.speed < ARRIVAL_SPEED)

    # -- the common checks ----------------------------------------------------------------------------
    def _command_trouble(self) -> str | None:
        now = self.now()
        pending = []
        last = self._commands[-1][0] if self._commands else None
        for handle, sent in self._commands:
            if handle.done:
                self._answered = self._answered or handle.ok
                superseded = handle.failure is Failure.CANCELLED and handle is not last
                if not handle.ok and not superseded:
                    return handle.reason or f"the drone refused {handle.command} ({handle.failure.value})"
            elif now - sent >= self.settings.command_timeout:
                return f"the drone did not accept {handle.command} within {self.settings.command_timeout:g} s"
            else:
                pending.append((handle, sent))
        self._commands = pending
        if not self._answered:
            self.progress.reset(now)
        return None

    def _flight_trouble(self, t: Telemetry) -> str | None:
        if self._was_armed and not t.armed and t.landed_state is not LandedState.ON_GROUND:
            return f"the drone is down: {self._drone_news() or 'its motors stopped in the air'}"
        if not self.needs_flight:
            return None
        if not t.armed or t.landed_state is LandedState.ON_GROUND:
            return f"the drone is on the ground: {self._drone_news() or 'it landed'}"
        if t.landed_state is LandedState.LANDING:
            return f"the drone is landing on its own (flight mode {t.flight_mode})"
        return None

    def _drone_news(self) -> str:
        """What the drone reported since the behavior started that explains why it is down (from the log)."""
        seen: dict[str, str] = {}
        for event in reversed(self.context.log.events()):
            if event.time < self.started_at - 1e-9:
                break
            if event.kind in _DOWN_EVENTS:
                seen.setdefault(event.kind, event.detail)
        kind = next((k for k in _DOWN_EVENTS if k in seen), None)
        return "" if kind is None else (_DOWN_EVENTS[kind] + seen[kind]).strip()
