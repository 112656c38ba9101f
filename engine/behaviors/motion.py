"""Motion behaviors (paper Table A.2) against the drone interface: TAKE_OFF, LAND, KEEP_HOVERING, KEEP_MOVING,
ROTATE and LOOK_AT_A_POINT here; the flights through points and patterns are in :mod:`.flight_patterns`.

``MOTION_BEHAVIORS`` lists every motion behavior class for the behavior library.
"""

from __future__ import annotations

import abc
import logging
import math
from typing import ClassVar

from aeroexec.drones import LandedState, Telemetry
from aeroexec.engine.behaviors.flight_control import (
    PROGRESS_STEP,
    RELATIVE_HEADINGS,
    YAW_PROGRESS_STEP,
    MotionBehavior,
    as_point,
    fmt_point,
    heading_to,
    horizontal_unit,
    wrap180,
    yaw_error,
)
from aeroexec.engine.behaviors.flight_patterns import Flip, FollowPath, GoToPoint, KeepLoitering
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess, Situation

logger = logging.getLogger(__name__)

ABORT_LAND_BELOW = 1.0  # m: a take-off stopped below this lands again rather than hover near the ground
HOVER_DRIFT_LIMIT = 1.5  # m: KEEP_HOVERING fails farther than this from where it stopped
SETTLED_SPEED = 0.25  # m/s: slower than this, a hovering drone has stopped
SPIN_RATE = 40.0  # deg/s: turns longer than FINISH_ARC spin at this yaw rate first
FINISH_ARC = 150.0  # degrees: the last part of a turn is a position hold with the final yaw (the short way)
SETTLED_YAW_RATE = 2.0  # deg/s: slower than this, a turn has stopped
# TAKE_OFF and LAND end once the beliefs agree (the catalog's final flight state), so that the next request's
# preconditions, checked against the beliefs, see the drone as it is.


class TakeOff(MotionBehavior):
    """TAKE_OFF: climb to ALTITUDE meters above the take-off point (the default altitude without it)."""

    behavior = "TAKE_OFF"
    needs_flight = False

    target: float | None = None  # the altitude climbed to; kept when the operator pauses and resumes

    def resume_from(self, paused: BehaviorProcess) -> None:
        self.target = getattr(paused, "target", None)

    def expected_duration(self) -> float | None:
        altitude = float(self.arguments.get("ALTITUDE", self.settings.default_altitude))
        return altitude / self.settings.climb_rate

    def begin(self, telemetry: Telemetry) -> None:
        if self.target is not None and telemetry.landed_state is not LandedState.ON_GROUND:
            x, y, _ = telemetry.position  # resumed in the air: climb on to the altitude it was taking off to
            self.command(self.drone.goto((x, y, self.target)))
            return
        if self.target is None:
            altitude = self.arguments.get("ALTITUDE", self.settings.default_altitude)
            self.target = telemetry.altitude + float(altitude)
        self.command(self.drone.takeoff(self.target))

    def step(self, telemetry: Telemetry) -> Outcome | None:
        error = abs(telemetry.altitude - self.target)
        if telemetry.landed_state is LandedState.IN_AIR and error <= self.settings.hover_altitude_tolerance:
            return Outcome.GOAL_ACHIEVED
        return self.no_progress(lambda: f"climbing to {self.target:.1f} m (at {telemetry.altitude:.1f} m)", error)

    def on_stop(self, outcome: Outcome) -> None:
        """An aborted take-off too close to the ground to hover safely lands again."""
        t = self.telemetry()
        if outcome is not Outcome.GOAL_ACHIEVED and t.armed and t.altitude < ABORT_LAND_BELOW:
            handle = self.drone.land()
            if handle.done and not handle.ok:
                logger.warning("TAKE_OFF: could not land after the aborted take-off: %s", handle.reason)
            return
        super().on_stop(outcome)


class Land(MotionBehavior):
    """LAND: descend vertically where the drone is; achieved on the ground (the drone disarms itself later)."""

    behavior = "LAND"
    needs_flight = False

    def expected_duration(self) -> float | None:
        return max(self.telemetry().altitude, 0.0) / self.settings.descent_rate

    def begin(self, telemetry: Telemetry) -> None:
        self.command(self.drone.land())

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if telemetry.landed_state is LandedState.ON_GROUND:
            return Outcome.GOAL_ACHIEVED
        return self.no_progress(lambda: f"descending (at {telemetry.altitude:.1f} m)", telemetry.altitude)


class KeepHovering(MotionBehavior):
    """KEEP_HOVERING: hold position, altitude and heading; fails if the drone lands, falls or drifts away."""

    behavior = "KEEP_HOVERING"

    def begin(self, telemetry: Telemetry) -> None:
        self.anchor: tuple[float, float, float] | None = None  # where it stopped
        self.command(self.drone.hold())

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if self.anchor is None:
            if telemetry.speed < SETTLED_SPEED:
                self.anchor = telemetry.position
                return None
            return self.no_progress(lambda: f"stopping (moving at {telemetry.speed:.1f} m/s)", telemetry.speed)
        drift = math.dist(telemetry.position, self.anchor)
        if drift > HOVER_DRIFT_LIMIT:
            return self.fail(f"the drone drifted {drift:.1f} m from where it hovers {fmt_point(self.anchor)}")
        return None

    def on_stop(self, outcome: Outcome) -> None:
        """Nothing to do: the drone already holds (a second hold would only queue one more command)."""


class KeepMoving(MotionBehavior):
    """KEEP_MOVING: fly at SPEED along DIRECTION (relative to the heading at the start, or up/down) until stopped."""

    behavior = "KEEP_MOVING"

    def begin(self, telemetry: Telemetry) -> None:
        direction = self.arguments["DIRECTION"]
        speed = float(self.arguments.get("SPEED", 1.0))
        if direction in ("UPWARD", "DOWNWARD"):
            self.unit = (0.0, 0.0, 1.0 if direction == "UPWARD" else -1.0)
        else:
            self.unit = horizontal_unit(telemetry.yaw + RELATIVE_HEADINGS[direction])
        self.speed = speed
        self.origin = telemetry.position
        self.command(self.drone.set_velocity(tuple(c * speed for c in self.unit)))  # type: ignore[arg-type]

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if self.speed < PROGRESS_STEP:
            return None  # moving at speed 0 is holding still
        travelled = sum((p - o) * u for p, o, u in zip(telemetry.position, self.origin, self.unit, strict=True))
        return self.no_progress(lambda: f"moving {self.arguments['DIRECTION']} ({travelled:.1f} m so far)", -travelled)


class Turn(MotionBehavior):
    """Turn in place by a signed angle: spin at a yaw rate while more than FINISH_ARC is left, then hold the
    position with the final yaw; achieved facing it and no longer turning. Subclasses say how far to turn
    (:meth:`plan_turn`, degrees counterclockwise).
    """

    progress_steps: ClassVar[tuple[float, ...]] = (YAW_PROGRESS_STEP,)

    @abc.abstractmethod
    def plan_turn(self, telemetry: Telemetry) -> float:
        """How far to turn from ``telemetry``'s yaw, degrees counterclockwise."""

    def check_situation(self) -> Situation | None:
        trouble = super().check_situation()
        if trouble is not None:
            return trouble
        t = self.telemetry()
        if abs(self.plan_turn(t)) <= self.settings.yaw_tolerance:
            return Situation(Outcome.GOAL_ACHIEVED, f"the drone already faces {t.yaw:.0f} degrees")
        return None

    def begin(self, telemetry: Telemetry) -> None:
        self.turn = self.plan_turn(telemetry)
        self.target = wrap180(telemetry.yaw + self.turn)
        self.place = telemetry.position
        self.turned = 0.0
        self.last_yaw, self.last_time = telemetry.yaw, self.now()
        self.finishing = False
        self._command_turn()

    def _command_turn(self) -> None:
        remaining = self.turn - self.turned
        if abs(remaining) <= FINISH_ARC:
            self.finishing = True
            self.command(self.drone.goto(self.place, yaw=self.target))
        else:
            self.command(self.drone.set_velocity((0.0, 0.0, 0.0), math.copysign(SPIN_RATE, remaining)))

    def step(self, telemetry: Telemetry) -> Outcome | None:
        change = wrap180(telemetry.yaw - self.last_yaw)
        rate = abs(change) / max(self.now() - self.last_time, 1e-6)
        self.turned += change
        self.last_yaw, self.last_time = telemetry.yaw, self.now()
        remaining = self.turn - self.turned
        if not self.finishing and abs(remaining) <= FINISH_ARC:
            self._command_turn()
        facing = yaw_error(telemetry.yaw, self.target) <= self.settings.yaw_tolerance
        if self.finishing and facing and rate < SETTLED_YAW_RATE:
            return Outcome.GOAL_ACHIEVED
        return self.no_progress(lambda: f"turning to {self.target:.0f} degrees (at {telemetry.yaw:.0f})",
                                abs(remaining))


class Rotate(Turn):
    """ROTATE: turn to ANGLE or by RELATIVE_ANGLE (degrees, counterclockwise); DIRECTION forces the turn's sense."""

    behavior = "ROTATE"

    def plan_turn(self, telemetry: Telemetry) -> float:
        sense = {"CLOCKWISE": -1.0, "COUNTERCLOCKWISE": 1.0}.get(self.arguments.get("DIRECTION", ""))
        relative = self.arguments.get("RELATIVE_ANGLE")
        if relative is not None:
            return float(relative) if sense is None else sense * abs(float(relative))
        turn = wrap180(float(self.arguments["ANGLE"]) - telemetry.yaw)
        if sense is None or abs(turn) <= self.settings.yaw_tolerance or turn * sense > 0:
            return turn
        return turn + sense * 360.0


class LookAtAPoint(Turn):
    """LOOK_AT_A_POINT: turn in place, the short way, to face COORDINATES."""

    behavior = "LOOK_AT_A_POINT"

    def plan_turn(self, telemetry: Telemetry) -> float:
        heading = heading_to(telemetry.position, as_point(self.arguments["COORDINATES"]))
        return 0.0 if heading is None else wrap180(heading - telemetry.yaw)


MOTION_BEHAVIORS: list[type[BehaviorProcess]] = [
    TakeOff, Land, KeepHovering, KeepMoving, Rotate, LookAtAPoint, GoToPoint, FollowPath, KeepLoitering, Flip,
]

__all__ = ["MOTION_BEHAVIORS", "Flip", "FollowPath", "GoToPoint", "KeepHovering", "KeepLoitering", "KeepMoving",
           "Land", "LookAtAPoint", "Rotate", "TakeOff", "Turn"]
