"""The rover's behaviors: DRIVE_TO_POINT, TURN, FOLLOW_WALL, DOCK, STOP and KEEP_STILL, on its own commands.

Each commands the rover without blocking and watches its telemetry each tick (paper Algorithm 2): the goal
reached is GOAL_ACHIEVED, a pressed bumper or no progress is WRONG_PROGRESS. A stopped motion behavior stops
the rover. PAY_ATTENTION_TO_VISUAL_MARKERS and SAY are aeroexec's own (:func:`rover_behaviors`).
"""

from __future__ import annotations

import math

from aeroexec.engine import BehaviorLibrary, BehaviorProcess, Outcome
from aeroexec.engine.behaviors import aerial_behaviors

from aeroexec_rover.rover import wrap180

ARRIVED = 0.15  # m
ALIGNED = 2.0  # degrees
STALL_TIME = 5.0  # s without getting closer is WRONG_PROGRESS


class RoverBehavior(BehaviorProcess):
    """A behavior that moves the rover: the bumper ends it, stopping it stops the rover."""

    def on_start(self) -> None:
        self.best = math.inf
        self.best_at = self.now()
        self.begin()

    def begin(self) -> None:
        """Send the first command."""

    def step(self) -> Outcome | None:
        return None

    def on_run(self) -> Outcome | None:
        if self.robot.bumper:
            return self.fail("the bumper is pressed: an obstacle is in the way")
        return self.step()

    def progress(self, error: float, doing: str) -> Outcome | None:
        """WRONG_PROGRESS when ``error`` has not shrunk for STALL_TIME seconds."""
        if error < self.best - 0.05:
            self.best, self.best_at = error, self.now()
        elif self.now() - self.best_at > STALL_TIME:
            return self.fail(f"no progress for {STALL_TIME:g} s while {doing}")
        return None

    def on_stop(self, outcome: Outcome) -> None:
        self.robot.stop()


class DriveToPoint(RoverBehavior):
    behavior = "DRIVE_TO_POINT"

    def begin(self) -> None:
        self.target = tuple(float(v) for v in self.arguments["COORDINATES"])[:2]
        handle = self.robot.drive_to(self.target, self.arguments.get("SPEED"))
        if handle.done and not handle.ok:
            self.reason = handle.reason

    def step(self) -> Outcome | None:
        if self.reason:
            return Outcome.WRONG_PROGRESS
        x, y, _ = self.telemetry().position
        error = math.dist((x, y), self.target)
        if error <= ARRIVED:
            return Outcome.GOAL_ACHIEVED
        return self.progress(error, f"driving to ({self.target[0]:.1f}, {self.target[1]:.1f})")


class Turn(RoverBehavior):
    behavior = "TURN"

    def begin(self) -> None:
        self.target = float(self.arguments["HEADING"])
        self.robot.turn_to(self.target)

    def step(self) -> Outcome | None:
        error = abs(wrap180(self.telemetry().yaw - self.target))
        return Outcome.GOAL_ACHIEVED if error <= ALIGNED else self.progress(error, f"turning to {self.target:g}°")


class FollowWall(RoverBehavior):
    """Keep the wall on the right at GAP meters while driving DISTANCE meters (a proportional steer)."""

    behavior = "FOLLOW_WALL"

    def begin(self) -> None:
        self.gap = float(self.arguments.get("GAP", 1.0))
        self.length = float(self.arguments["DISTANCE"])
        self.driven = 0.0
        self.last = self.telemetry().position

    def step(self) -> Outcome | None:
        position = self.telemetry().position
        self.driven += math.dist(position[:2], self.last[:2])
        self.last = position
        if self.driven >= self.length:
            return Outcome.GOAL_ACHIEVED
        right = self.robot.distance_ahead(-90.0, reach=3 * self.gap)
        if right >= 3 * self.gap:
            return self.fail("no wall on the right")
        front = self.robot.distance_ahead(0.0, reach=2 * self.gap)
        turn = 60.0 if front < self.gap else max(-40.0, min(40.0, 40.0 * (right - self.gap)))
        self.robot.set_motion(0.5 if front >= self.gap else 0.0, -turn if front >= self.gap else turn)
        return self.progress(self.length - self.driven, "following the wall")


class Dock(RoverBehavior):
    """Drive to the dock; achieved once the rover is docked (charging)."""

    behavior = "DOCK"

    def begin(self) -> None:
        if self.robot.dock_position is None:
            self.reason = "this yard has no dock"
            return
        self.robot.drive_to(self.robot.dock_position)

    def step(self) -> Outcome | None:
        if self.reason:
            return Outcome.WRONG_PROGRESS
        if self.robot.docked:
            return Outcome.GOAL_ACHIEVED
        x, y, _ = self.telemetry().position
        return self.progress(math.dist((x, y), self.robot.dock_position), "driving to the dock")

    def on_stop(self, outcome: Outcome) -> None:
        if outcome is not Outcome.GOAL_ACHIEVED:
            super().on_stop(outcome)


class Stop(RoverBehavior):
    behavior = "STOP"

    def begin(self) -> None:
        self.robot.stop()

    def step(self) -> Outcome | None:
        return Outcome.GOAL_ACHIEVED if abs(self.telemetry().speed) < 0.02 else None


class KeepStill(RoverBehavior):
    """Recurrent: hold the rover where it is until another behavior moves it."""

    behavior = "KEEP_STILL"

    def begin(self) -> None:
        self.robot.stop()

    def on_run(self) -> Outcome | None:
        return None  # the bumper does not end standing still


def rover_behaviors() -> BehaviorLibrary:
    """The rover's behaviors, with PAY_ATTENTION_TO_VISUAL_MARKERS and SAY taken from aeroexec's library."""
    aerial = aerial_behaviors()
    reused = [aerial.get("PAY_ATTENTION_TO_VISUAL_MARKERS"), aerial.get("SAY")]
    return BehaviorLibrary([DriveToPoint, Turn, FollowWall, Dock, Stop, KeepStill, *reused])
