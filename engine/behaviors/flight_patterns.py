"""Motion behaviors that fly through points or patterns: GO_TO_POINT, FOLLOW_PATH, KEEP_LOITERING and FLIP.

Points are local ENU meters from home (the specialist has placed ``geo:`` points already). GO_TO_POINT flies the
route of the path planner around the obstacles it knows (straight when there is no obstacle map); the other flights
are straight lines (SPLINE is not implemented: a straight line into an obstacle ends in WRONG_PROGRESS when the
drone hits it). GO_TO_POINT and FOLLOW_PATH expect their flight to take its distance at its speed: their timeouts
grow with it."""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import ClassVar

from aeroexec.drones import Telemetry, Vector
from aeroexec.engine.behaviors.flight_control import (
    PROGRESS_STEP,
    RELATIVE_HEADINGS,
    YAW_PROGRESS_STEP,
    MotionBehavior,
    as_point,
    fmt_point,
    heading_to,
    horizontal_unit,
    offset,
    wrap180,
    yaw_error,
)
from aeroexec.engine.behaviors.planning import RouteRequest
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import Situation

logger = logging.getLogger(__name__)

LOOK_RECOMMAND_PERIOD = 0.5  # s: GO_TO_POINT re-aims at POINT_TO_LOOK_DURING_FLIGHT at most this often
LOOK_RECOMMAND_ANGLE = 10.0  # degrees: ... when the heading to it moved this much
LOOK_FINAL_DISTANCE = 1.0  # m: closer than this, GO_TO_POINT turns to its final yaw
LOITER_COMMAND_PERIOD = 0.2  # s between KEEP_LOITERING's velocity setpoints
LOITER_GAIN = 1.5  # 1/s: how briskly KEEP_LOITERING closes its distance to the pattern
LOITER_YAW_GAIN = 2.0  # 1/s: how briskly it turns to face its travel
LOITER_LEAD = 0.1  # m: KEEP_LOITERING flies along the pattern's direction this far ahead of its nearest point
LOITER_MAX_DEVIATION = 2.0  # m: once on its pattern, farther than this from it is WRONG_PROGRESS
LOITER_ON_PATTERN = 0.5  # m: this close, the drone has joined its pattern
LOITER_JOIN_BRAKING = 1.0  # m/s^2: KEEP_LOITERING flies to its pattern no faster than it stops at this deceleration
DEFAULT_RADIUS = 2.0  # m: a CIRCLE without RADIUS
DEFAULT_SIDE = 4.0  # m: a SQUARE without SIDE
FLIP_JOG = 1.5  # m: the length of FLIP's jog
FLIP_SPEED = 8.0  # m/s: the speed FLIP asks for (the vehicle's acceleration limits it)


def flight_time(distance: float, speed: float, stops: int = 1) -> float:
    """Seconds to fly ``distance`` meters at ``speed`` m/s, with a few seconds to speed up and stop each time."""
    return distance / max(speed, 0.1) + 3.0 * stops


class PointFlight(MotionBehavior):
    """Flies to one point after another with the drone's go-to; subclasses say what comes next."""

    progress_steps: ClassVar[tuple[float, ...]] = (PROGRESS_STEP, YAW_PROGRESS_STEP)

    def fly_to(self, point: Vector, yaw: float | None = None, speed: float | None = None) -> None:
        self.point, self.yaw, self.speed = point, yaw, speed
        self.progress.reset(self.now())
        self.command(self.drone.goto(point, yaw=yaw, speed=speed))

    def reached(self, telemetry: Telemetry, settle: bool = True) -> bool:
        """At the current point (and nearly still when ``settle``), facing its yaw if it has one."""
        near = (self.arrived(telemetry, self.point) if settle
                else math.dist(telemetry.position, self.point) <= self.settings.position_tolerance)
        return near and (self.yaw is None or yaw_error(telemetry.yaw, self.yaw) <= self.settings.yaw_tolerance)

    def approach(self, telemetry: Telemetry) -> Outcome | None:
        """WRONG_PROGRESS when neither the distance to the point nor the yaw error shrank for a while."""
        distance = math.dist(telemetry.position, self.point)
        turn = 0.0 if self.yaw is None else yaw_error(telemetry.yaw, self.yaw)
        return self.no_progress(lambda: f"toward {fmt_point(self.point)} ({distance:.1f} m away)", distance, turn)


class GoToPoint(PointFlight):
    """GO_TO_POINT: fly to COORDINATES (or RELATIVE_COORDINATES from where the drone is when asked) at SPEED,
    ending with YAW_ANGLE_AT_THE_END or facing POINT_TO_LOOK_AT_THE_END; POINT_TO_LOOK_DURING_FLIGHT aims the
    drone on the way; TIME (seconds on the engine's clock) sets the speed when SPEED is not given.
    """

    behavior = "GO_TO_POINT"

    def prepare(self) -> None:
        t = self.telemetry()
        coordinates = self.arguments.get("COORDINATES")
        if coordinates is not None:
            self.destination = as_point(coordinates)
        else:
            self.destination = offset(t.position, self.arguments["RELATIVE_COORDINATES"])
        self.bindings["?DESTINATION"] = self.destination
        yaw = self.arguments.get("YAW_ANGLE_AT_THE_END")
        look = self.arguments.get("POINT_TO_LOOK_AT_THE_END")
        if yaw is None and look is not None:
            yaw = heading_to(self.destination, as_point(look))
        self.final_yaw = None if yaw is None else wrap180(float(yaw))

    def expected_duration(self) -> float | None:
        speed = self.arguments.get("SPEED") or self.settings.cruise_speed
        return flight_time(math.dist(self.telemetry().position, self.destination), float(speed))

    def check_situation(self) -> Situation | None:
        trouble = super().check_situation()
        if trouble is not None:
            return trouble
        t = self.telemetry()
        facing = self.final_yaw is None or yaw_error(t.yaw, self.final_yaw) <= self.settings.yaw_tolerance
        if math.dist(t.position, self.destination) <= self.settings.position_tolerance and facing:
            return Situation(Outcome.GOAL_ACHIEVED, f"the drone is already at {fmt_point(self.destination)}")
        # avoiding obstacles (Table A.2): answered now when a few distance queries decide, else searched on the
        # planning worker once the behavior runs
        self.request = RouteRequest(self.context, self.destination)
        self.route: list[Vector] | None = None
        answer = self.request.answer(self.now())
        if answer is not None:
            self.route = answer[0]
            if not self.route:  # Table 3's goal and environment conflicts
                return Situation(Outcome.FAILED_PRECONDITIONS, self._conflict(answer[1]))
        return None

    def _conflict(self, detail: str) -> str:
        conflict = ("The destination is too far for behavior" if "outside the bounds" in detail
                    else "There is an impassable barrier to complete behavior")
        return f"{conflict} {self.name} ({detail})"

    def begin(self, telemetry: Telemetry) -> None:
        self.look = self.arguments.get("POINT_TO_LOOK_DURING_FLIGHT")
        self.aimed_at = -math.inf
        self.leg = 0
        if self.route is None:  # RUNNING while the planning worker searches; the drone holds where it is
            self.request.submit()
            self.command(self.drone.hold())
            return
        self._fly_leg(telemetry)

    def _route_found(self, telemetry: Telemetry) -> Outcome | None:
        """The planning worker's answer, once it is back: fly the route, or end saying why there is none."""
        answer = self.request.answer(self.now())
        if answer is None:
            self.progress.reset(self.now())  # waiting for a plan is not a lack of progress
            return None
        route, detail = answer
        if not route:
            if self.request.error:
                return self.fail(self.request.error)
            self.reason = self._conflict(detail)
            return Outcome.FAILED_PRECONDITIONS
        self.route = route
        if len(route) > 1:
            logger.info("%s: %s", self.name, detail)
        self._fly_leg(telemetry)
        return None

    def _fly_leg(self, telemetry: Telemetry) -> None:
        """Fly to the next waypoint of the route; the last one is the destination, with the final yaw."""
        on_the_way = self.leg < len(self.route) - 1 and self.look is None  # face the travel
        self.fly_to(self.route[self.leg], None if on_the_way else self._yaw_now(telemetry), self._speed(telemetry))

    def _speed(self, telemetry: Telemetry) -> float | None:
        speed = self.arguments.get("SPEED")
        arrive_by = self.arguments.get("TIME")
        if speed is None and arrive_by is not None and arrive_by > self.now():
            speed = min(max(math.dist(telemetry.position, self.destination) / (arrive_by - self.now()), 0.1), 30.0)
        return None if speed is None else float(speed)

    def _yaw_now(self, telemetry: Telemetry) -> float | None:
        """The yaw to fly with: toward the look point on the way, the final yaw near the end."""
        if self.look is None or math.dist(telemetry.position, self.destination) <= LOOK_FINAL_DISTANCE:
            return self.final_yaw
        heading = heading_to(telemetry.position, as_point(self.look))
        return self.final_yaw if heading is None else heading

    def _aim(self, yaw: float | None) -> None:
        """Send the go-to again with ``yaw`` when it is the final one or turned noticeably from the last."""
        small_turn = (yaw is not None and self.yaw is not None and yaw_error(yaw, self.yaw) <= LOOK_RECOMMAND_ANGLE)
        if yaw == self.yaw or (small_turn and yaw != self.final_yaw):
            return
        self.aimed_at = self.now()
        self.yaw = yaw
        self.command(self.drone.goto(self.point, yaw=yaw, speed=self.speed))

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if self.route is None:
            return self._route_found(telemetry)
        if self.look is not None and self.now() - self.aimed_at >= LOOK_RECOMMAND_PERIOD:
            self._aim(self._yaw_now(telemetry))
        if self.leg < len(self.route) - 1:  # a waypoint on the way: pass it without stopping
            if math.dist(telemetry.position, self.point) <= self.settings.position_tolerance * 2:
                self.leg += 1
                self._fly_leg(telemetry)
                return None
            return self.approach(telemetry)
        if self.final_yaw is None or self.yaw == self.final_yaw:
            accept = self.arguments.get("ACCEPTANCE_RADIUS")
            if self.reached(telemetry) or (accept is not None and self._within(telemetry, float(accept))):
                return Outcome.GOAL_ACHIEVED
        return self.approach(telemetry)

    def _within(self, telemetry: Telemetry, radius: float) -> bool:
        """Within the acceptance radius of the destination (facing its yaw): passed without stopping."""
        return math.dist(telemetry.position, self.destination) <= radius and (
            self.final_yaw is None or yaw_error(telemetry.yaw, self.final_yaw) <= self.settings.yaw_tolerance)

    def on_stop(self, outcome: Outcome) -> None:
        self.request.cancel()  # a search still under way is no longer wanted
        super().on_stop(outcome)


class FollowPath(PointFlight):
    """FOLLOW_PATH: fly through the points of PATH in order (at SPEED when given); achieved at the last one."""

    behavior = "FOLLOW_PATH"

    def prepare(self) -> None:
        self.points = [as_point(p) for p in self.arguments["PATH"]]

    def check_situation(self) -> Situation | None:
        trouble = super().check_situation()
        if trouble is not None:
            return trouble
        t = self.telemetry()
        if all(math.dist(t.position, p) <= self.settings.position_tolerance for p in self.points):
            return Situation(Outcome.GOAL_ACHIEVED, f"the drone is already at {fmt_point(self.points[-1])}")
        return None

    def begin(self, telemetry: Telemetry) -> None:
        self.index = 0
        if math.dist(telemetry.position, self.points[0]) <= self.settings.position_tolerance:
            self.index = 1
        self.fly_to(self.points[self.index], speed=self._speed())

    def _speed(self) -> float | None:
        speed = self.arguments.get("SPEED")
        return None if speed is None else float(speed)

    def expected_duration(self) -> float | None:
        points = [self.telemetry().position, *self.points]
        length = sum(math.dist(a, b) for a, b in zip(points, points[1:], strict=False))
        return flight_time(length, self._speed() or self.settings.cruise_speed, stops=len(self.points))

    def step(self, telemetry: Telemetry) -> Outcome | None:
        last = self.index == len(self.points) - 1
        if self.reached(telemetry, settle=last):
            logger.info("%s: point %d of %d reached %s", self.name, self.index + 1, len(self.points),
                        fmt_point(self.point))
            if last:
                return Outcome.GOAL_ACHIEVED
            self.index += 1
            self.fly_to(self.points[self.index], speed=self._speed())
            return None
        return self.approach(telemetry)


class Flip(PointFlight):
    """FLIP: a short sharp jog in DIRECTION (relative to the heading) and straight back to the start point."""

    behavior = "FLIP"

    def begin(self, telemetry: Telemetry) -> None:
        direction = horizontal_unit(telemetry.yaw + RELATIVE_HEADINGS[self.arguments.get("DIRECTION", "FRONT")])
        self.start = telemetry.position
        self.returning = False
        self.fly_to(offset(self.start, tuple(c * FLIP_JOG for c in direction)), telemetry.yaw, FLIP_SPEED)

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if not self.returning and self.reached(telemetry, settle=False):
            self.returning = True
            self.fly_to(self.start, self.yaw, FLIP_SPEED)
            return None
        if self.returning and self.reached(telemetry):
            return Outcome.GOAL_ACHIEVED
        return self.approach(telemetry)


class ClosedPattern:
    """A closed horizontal polyline (the corners in flight order) flown at constant altitude, by arc length."""

    def __init__(self, corners: Sequence[tuple[float, float]]) -> None:
        self.corners = [*corners, corners[0]]
        self.legs = list(zip(self.corners, self.corners[1:], strict=False))
        self.starts = [0.0]
        for a, b in self.legs:
            self.starts.append(self.starts[-1] + math.dist(a, b))
        self.length = self.starts[-1]

    @classmethod
    def circle(cls, center: Sequence[float], radius: float, clockwise: bool, segments: int = 72) -> ClosedPattern:
        sense = -1.0 if clockwise else 1.0
        return cls([(center[0] + radius * math.cos(sense * 2 * math.pi * i / segments),
                     center[1] + radius * math.sin(sense * 2 * math.pi * i / segments)) for i in range(segments)])

    @classmethod
    def square(cls, center: Sequence[float], side: float, clockwise: bool) -> ClosedPattern:
        h = side / 2.0
        corners = [(h, h), (-h, h), (-h, -h), (h, -h)]  # counterclockwise
        if clockwise:
            corners.reverse()
        return cls([(center[0] + x, center[1] + y) for x, y in corners])

    def nearest(self, x: float, y: float) -> tuple[float, float, float, float]:
        """(distance, nearest x, nearest y, its arc length) for the horizontal point (x, y)."""
        best = (math.inf, x, y, 0.0)
        for ((ax, ay), (bx, by)), start, end in zip(self.legs, self.starts[:-1], self.starts[1:], strict=True):
            dx, dy = bx - ax, by - ay
            length2 = dx * dx + dy * dy
            f = 0.0 if length2 <= 0.0 else min(max(((x - ax) * dx + (y - ay) * dy) / length2, 0.0), 1.0)
            px, py = ax + f * dx, ay + f * dy
            d = math.hypot(x - px, y - py)
            if d < best[0]:
                best = (d, px, py, start + f * (end - start))
        return best

    def tangent(self, s: float) -> tuple[float, float]:
        """The unit direction of flight at arc length ``s`` (wrapping round)."""
        s %= self.length
        i = next(i for i, end in enumerate(self.starts[1:]) if s < end or i == len(self.legs) - 1)
        (ax, ay), (bx, by) = self.legs[i]
        n = math.hypot(bx - ax, by - ay)
        return (bx - ax) / n, (by - ay) / n


class KeepLoitering(MotionBehavior):
    """KEEP_LOITERING: after DELAY seconds, keep flying a CIRCLE of RADIUS or a SQUARE of SIDE centred where it
    started, CLOCKWISE or not (clockwise by default), facing its travel, at a speed that suits the size.
    """

    behavior = "KEEP_LOITERING"

    def begin(self, telemetry: Telemetry) -> None:
        self.center = telemetry.position
        clockwise = self.arguments.get("CLOCKWISE")
        clockwise = True if clockwise is None else bool(clockwise)
        self.pattern: ClosedPattern | None = None  # a circle of radius 0: hover where it is
        if self.arguments.get("SHAPE", "CIRCLE") == "SQUARE":
            side = float(self.arguments.get("SIDE") or DEFAULT_SIDE)
            self.pattern, size = ClosedPattern.square(self.center, side, clockwise), side / 2.0
        else:
            radius = self.arguments.get("RADIUS")
            size = float(DEFAULT_RADIUS if radius is None else radius)
            if size > 0.0:
                self.pattern = ClosedPattern.circle(self.center, size, clockwise)
        self.speed = min(2.0, max(0.5, 0.5 * size))  # m/s: 1 m/s on a circle of 2 m
        self.delay = float(self.arguments.get("DELAY") or 0.0)
        self.joined = False
        self.sent_at = -math.inf
        self.odometer = 0.0
        self.last = telemetry.position
        self.command(self.drone.hold())

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if self.pattern is None or self.elapsed < self.delay:
            self.progress.reset(self.now())
            return None
        x, y, z = telemetry.position
        off, px, py, s = self.pattern.nearest(x, y)
        tx, ty = self.pattern.tangent(s + LOITER_LEAD)  # a little ahead: past a corner it already turns
        self.joined = self.joined or off <= LOITER_ON_PATTERN
        if self.joined and off > LOITER_MAX_DEVIATION:
            return self.fail(f"the drone left its {self.arguments.get('SHAPE', 'CIRCLE').lower()} by {off:.1f} m")
        if self.now() - self.sent_at >= LOITER_COMMAND_PERIOD - 1e-9:
            self.sent_at = self.now()
            # toward the pattern no faster than the drone can stop on it (a wide circle is joined from its center)
            reach = min(LOITER_GAIN * off, math.sqrt(2.0 * LOITER_JOIN_BRAKING * off))
            vx = tx * self.speed + (reach * (px - x) / off if off > 1e-9 else 0.0)
            vy = ty * self.speed + (reach * (py - y) / off if off > 1e-9 else 0.0)
            vz = min(max(LOITER_GAIN * (self.center[2] - z), -0.5), 0.5)
            facing = wrap180(math.degrees(math.atan2(vy, vx)) - telemetry.yaw)
            self.command(self.drone.set_velocity((vx, vy, vz), max(-30.0, min(30.0, LOITER_YAW_GAIN * facing))))
        self.odometer += math.dist(telemetry.position, self.last)
        self.last = telemetry.position
        return self.no_progress(lambda: f"loitering ({self.odometer:.1f} m flown)", -self.odometer)
