"""Motion with targets (paper Table A.2): FOLLOW_OBJECT_IMAGE, TRACK_OBJECT_IMAGE, ALIGN_OVER_IMAGE,
LAND_ON_MOVING_PLATFORM, TAKE_OFF_FROM_MOVING_PLATFORM and TOUCH_MOVING_OBJECT, by visual servoing.

A target is named by the IMAGE argument as the cameras report it (``red_box``, ``rover``, ``marker_42``);
LAND_ON_MOVING_PLATFORM looks for a landing platform, TOUCH_MOVING_OBJECT without IMAGE for the nearest
object in view. Targets are estimated from what the cameras see now (:mod:`.target_tracking`): a target not
yet in view is searched for by turning in place (one full turn at most); once found, losing sight of it
for longer than ``lost_sight_time`` seconds (``EngineSettings.extra``, default 3) ends the behavior with
WRONG_PROGRESS "lost sight of X". The drone is flown with velocity setpoints: the target's estimated
velocity plus a correction toward where the drone should be.

Settings read from ``EngineSettings.extra``: ``lost_sight_time`` (s, 3.0), ``follow_distance`` (m, 3.0).
"""

from __future__ import annotations

import logging
import math
from typing import ClassVar

from aeroexec.drones import LandedState, Telemetry, Vector
from aeroexec.engine.behaviors.flight_control import (
    ARRIVAL_SPEED,
    PROGRESS_STEP,
    MotionBehavior,
    fmt_point,
    heading_to,
    wrap180,
)
from aeroexec.engine.behaviors.motion import TakeOff
from aeroexec.engine.behaviors.target_tracking import TARGET_PROCESSES, Track, TrackStore, observe, target_tracks
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess

logger = logging.getLogger(__name__)

LOST_SIGHT_TIME = 3.0  # s a target may stay unseen before WRONG_PROGRESS
SEARCH_RATE = 30.0  # deg/s: the turn in place that looks for a target not in view
GAIN = 1.0  # 1/s: velocity per meter of position error
MAX_SPEED = 4.0  # m/s: horizontal speed the servoing asks for at most
MAX_CLIMB = 1.0  # m/s: vertical speed it asks for at most
YAW_GAIN = 1.5  # 1/s: yaw rate per degree of heading error
MAX_YAW_RATE = 45.0  # deg/s
FOLLOW_DISTANCE = 3.0  # m: FOLLOW_OBJECT_IMAGE's horizontal distance to its target
BEHIND_PULL = 0.5  # how strongly FOLLOW_OBJECT_IMAGE swings round behind a moving target (1: straight behind)
FOLLOW_SLACK = 1.0  # m: within this of the follow distance, the follower is on station (no stall watch)
STOPPED_SPEED = 0.1  # m/s: a target slower than this has stopped ...
STOPPED_TIME = 2.0  # s: ... once it stayed that slow this long
FACE_DISTANCE = 1.5  # m: closer than this horizontally, ALIGN/LAND/TOUCH stop turning toward the target
HOLD_DRIFT = 1.5  # m: TRACK_OBJECT_IMAGE fails farther than this from where it keeps position
APPROACH_HEIGHT = 2.0  # m above the deck: LAND_ON_MOVING_PLATFORM matches the platform's motion there
DESCEND_ALIGN = 0.3  # m: aligned this well with the deck (and matching its speed), the drone descends ...
MATCHED_SPEED = 0.3  # m/s: ... its speed relative to the deck below this
DESCEND_PAUSE = 0.6  # m: farther off the deck's center, the descent pauses until aligned again
DESCENT_SPEED = 0.5  # m/s: the descent onto the deck or toward an object
ON_DECK_HEIGHT = 0.15  # m: landed higher than this above home, the drone stands on the deck
TOUCH_HEIGHT = 0.3  # m: TOUCH_MOVING_OBJECT aims this far above the object's center ...
TOUCH_REACH = 0.4  # m: ... and has touched it once its center is this close to the object's


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def _horizontal(a: Vector, b: Vector) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


class TargetBehavior(MotionBehavior):
    """Visual servoing on one target: find it, keep an estimate of it, fly with velocity setpoints.

    Subclasses write :meth:`start` (once, with the first telemetry) and :meth:`servo` (each tick the target
    is tracked); :meth:`find` picks a target when IMAGE does not name one.
    """

    #: What the operator reads for a target not yet found (e.g. "a landing platform").
    wanted: ClassVar[str] = "the target"

    # -- hooks ------------------------------------------------------------------------------------------
    def start(self, telemetry: Telemetry) -> None:
        """Initialize (the target may not be in view yet)."""

    def servo(self, telemetry: Telemetry, track: Track) -> Outcome | None:
        """One tick with the target's estimate: command the drone, return the outcome or None."""
        return None

    def find(self, store: TrackStore, telemetry: Telemetry) -> str | None:
        """The name of a target among what the cameras see now, when IMAGE names none."""
        return None

    # -- the lifecycle ----------------------------------------------------------------------------------
    def begin(self, telemetry: Telemetry) -> None:
        image = self.arguments.get("IMAGE")
        self.target: str | None = None if image in (None, "") else str(image).strip()
        self.store = target_tracks(self.context)
        if self.target is not None:
            self.store.want(self.target)
        self.lost_after = float(self.settings.extra.get("lost_sight_time", LOST_SIGHT_TIME))
        self.anchor = telemetry.position
        self.searched, self.last_yaw = 0.0, telemetry.yaw
        self.start(telemetry)

    def on_stop(self, outcome: Outcome) -> None:
        if getattr(self, "target", None) is not None:
            self.store.unwant(self.target)  # type: ignore[arg-type]
        self.hold()  # velocity setpoints must not outlive the behavior, whatever its end

    def step(self, telemetry: Telemetry) -> Outcome | None:
        now = self.now()
        store = observe(self.context, now)
        if self.target is None:
            self.target = self.find(store, telemetry)
            if self.target is not None:
                self.store.want(self.target)
                logger.info("%s: found %s", self.name, self.target)
        track = store.get(self.target) if self.target is not None else None
        if track is not None and track.seen_at < self.started_at - self.lost_after:
            track = None  # an old sighting from before this behavior
        if track is None:
            return self.search(telemetry)
        unseen = now - track.seen_at
        if unseen > self.lost_after:
            return self.fail(f"lost sight of {self.target} (not seen for {unseen:.1f} s)")
        return self.servo(telemetry, track)

    def search(self, telemetry: Telemetry) -> Outcome | None:
        """Turn in place looking for the target; WRONG_PROGRESS after a full turn without it."""
        self.searched += abs(wrap180(telemetry.yaw - self.last_yaw))
        self.last_yaw = telemetry.yaw
        what = self.target or self.wanted
        if self.searched >= 360.0:
            return self.fail(f"{what} is not in sight (not found in a full turn)")
        self.progress.reset(self.now())
        self.fly(telemetry, self.anchor, yaw_rate=SEARCH_RATE)
        return None

    # -- helpers ----------------------------------------------------------------------------------------
    def fly(self, telemetry: Telemetry, point: Vector, feed: Vector = (0.0, 0.0, 0.0), yaw: float | None = None,
            yaw_rate: float | None = None, max_descent: float = MAX_CLIMB) -> None:
        """A velocity setpoint toward ``point`` on top of ``feed`` (the target's velocity), turning to ``yaw``."""
        x, y, z = telemetry.position
        vx, vy = feed[0] + GAIN * (point[0] - x), feed[1] + GAIN * (point[1] - y)
        speed = math.hypot(vx, vy)
        if speed > MAX_SPEED:
            vx, vy = vx * MAX_SPEED / speed, vy * MAX_SPEED / speed
        vz = max(-max_descent, min(MAX_CLIMB, feed[2] + GAIN * (point[2] - z)))
        if yaw_rate is None:
            yaw_rate = 0.0 if yaw is None else _clamp(YAW_GAIN * wrap180(yaw - telemetry.yaw), MAX_YAW_RATE)
        self.command(self.drone.set_velocity((vx, vy, vz), yaw_rate))

    def relative_speed(self, telemetry: Telemetry, track: Track) -> float:
        """The drone's horizontal speed relative to the target's."""
        return math.hypot(telemetry.velocity[0] - track.velocity[0], telemetry.velocity[1] - track.velocity[1])

    @staticmethod
    def ground_feed(track: Track) -> Vector:
        return (track.velocity[0], track.velocity[1], 0.0)


class FollowObjectImage(TargetBehavior):
    """FOLLOW_OBJECT_IMAGE: keep ``follow_distance`` meters (horizontally, at the altitude it started at)
    from IMAGE, on the side the drone is on (behind a target moving away), facing it. Achieved once the target
    has stopped for a while and the drone holds at the distance; a target that keeps moving is followed until
    the timeout.
    """

    behavior = "FOLLOW_OBJECT_IMAGE"

    def start(self, telemetry: Telemetry) -> None:
        self.distance = float(self.settings.extra.get("follow_distance", FOLLOW_DISTANCE))
        self.altitude = telemetry.altitude
        self.stopped_since: float | None = None

    def servo(self, telemetry: Telemetry, track: Track) -> Outcome | None:
        now = self.now()
        target = track.predict(now)
        x, y, _ = telemetry.position
        away = _horizontal(telemetry.position, target)
        ux, uy = (x - target[0]) / max(away, 1e-3), (y - target[1]) / max(away, 1e-3)
        if track.ground_speed > STOPPED_SPEED:  # swing round behind a moving target
            ux -= BEHIND_PULL * track.velocity[0] / track.ground_speed
            uy -= BEHIND_PULL * track.velocity[1] / track.ground_speed
        norm = math.hypot(ux, uy)
        if norm < 1e-3:  # right above a still target: back off along the heading
            ux, uy, norm = -math.cos(math.radians(telemetry.yaw)), -math.sin(math.radians(telemetry.yaw)), 1.0
        ux, uy = ux / norm, uy / norm
        point = (target[0] + ux * self.distance, target[1] + uy * self.distance, self.altitude)
        self.fly(telemetry, point, self.ground_feed(track), yaw=heading_to(telemetry.position, target))
        error = abs(away - self.distance)
        if track.ground_speed >= STOPPED_SPEED:
            self.stopped_since = None
        elif self.stopped_since is None:
            self.stopped_since = now
        if (self.stopped_since is not None and now - self.stopped_since >= STOPPED_TIME
                and error <= self.settings.position_tolerance and telemetry.speed < ARRIVAL_SPEED):
            return Outcome.GOAL_ACHIEVED
        if error <= FOLLOW_SLACK:
            self.progress.reset(now)
            return None
        return self.no_progress(
            lambda: f"closing on {self.target} ({away:.1f} m away, following at {self.distance:g} m)", error)


class TrackObjectImage(TargetBehavior):
    """TRACK_OBJECT_IMAGE: keep the position it started at and turn to keep IMAGE in the middle of the view."""

    behavior = "TRACK_OBJECT_IMAGE"

    def start(self, telemetry: Telemetry) -> None:
        self.place = telemetry.position

    def servo(self, telemetry: Telemetry, track: Track) -> Outcome | None:
        drift = math.dist(telemetry.position, self.place)
        if drift > HOLD_DRIFT:
            return self.fail(f"the drone drifted {drift:.1f} m from where it keeps position {fmt_point(self.place)}")
        self.fly(telemetry, self.place, yaw=heading_to(telemetry.position, track.predict(self.now())))
        self.progress.reset(self.now())
        return None


class AlignOverImage(TargetBehavior):
    """ALIGN_OVER_IMAGE: fly at the current altitude to right above IMAGE (matching its motion); achieved
    within the position tolerance of it horizontally, at that altitude and moving with it."""

    behavior = "ALIGN_OVER_IMAGE"

    def start(self, telemetry: Telemetry) -> None:
        self.altitude = telemetry.altitude

    def servo(self, telemetry: Telemetry, track: Track) -> Outcome | None:
        target = track.predict(self.now())
        off = _horizontal(telemetry.position, target)
        yaw = heading_to(telemetry.position, target) if off > FACE_DISTANCE else None
        self.fly(telemetry, (target[0], target[1], self.altitude), self.ground_feed(track), yaw=yaw)
        if (off <= self.settings.position_tolerance and self.relative_speed(telemetry, track) < ARRIVAL_SPEED
                and abs(telemetry.altitude - self.altitude) <= self.settings.hover_altitude_tolerance):
            return Outcome.GOAL_ACHIEVED
        return self.no_progress(lambda: f"aligning over {self.target} ({off:.1f} m off)", off)


class LandOnMovingPlatform(TargetBehavior):
    """LAND_ON_MOVING_PLATFORM: find a landing platform (turning in place if none is in view), fly to
    ``APPROACH_HEIGHT`` above its deck matching its velocity, descend while staying over the deck's center
    (pausing when blown off it), and touch down on the deck; achieved once landed on it. Landing beside
    it, on the ground, is WRONG_PROGRESS.
    """

    behavior = "LAND_ON_MOVING_PLATFORM"
    needs_flight = False
    progress_steps: ClassVar[tuple[float, ...]] = (PROGRESS_STEP, PROGRESS_STEP)
    wanted = "a landing platform"

    def start(self, telemetry: Telemetry) -> None:
        self.descending = False

    def find(self, store: TrackStore, telemetry: Telemetry) -> str | None:
        platforms = store.platforms()
        if not platforms:
            return None
        return min(platforms, key=lambda p: math.dist(p.position, telemetry.position)).name

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if telemetry.landed_state is LandedState.ON_GROUND:
            return self.touched_down(telemetry)
        if telemetry.landed_state is LandedState.LANDING:
            return self.fail(f"the drone is landing on its own (flight mode {telemetry.flight_mode})")
        return super().step(telemetry)

    def touched_down(self, telemetry: Telemetry) -> Outcome | None:
        if telemetry.altitude <= ON_DECK_HEIGHT:
            return self.fail(f"the drone landed on the ground at {fmt_point(telemetry.position)}, "
                             f"not on the deck of {self.target or 'the platform'}")
        return Outcome.GOAL_ACHIEVED

    def servo(self, telemetry: Telemetry, track: Track) -> Outcome | None:
        deck = track.predict(self.now())
        off = _horizontal(telemetry.position, deck)
        above = telemetry.altitude - deck[2]
        if not self.descending:
            point = (deck[0], deck[1], deck[2] + APPROACH_HEIGHT)
            yaw = heading_to(telemetry.position, deck) if off > FACE_DISTANCE else None
            self.fly(telemetry, point, self.ground_feed(track), yaw=yaw)
            if (off <= DESCEND_ALIGN and self.relative_speed(telemetry, track) < MATCHED_SPEED
                    and abs(telemetry.altitude - point[2]) <= 0.5):
                self.descending = True
                self.progress.reset(self.now())
                logger.info("%s: over the deck of %s, descending", self.name, self.target)
            return self.no_progress(lambda: f"approaching the deck of {self.target} ({off:.1f} m off)", off,
                                    abs(telemetry.altitude - point[2]))
        bottom = deck[2] - 1.0 if off <= DESCEND_PAUSE else telemetry.altitude  # keep descending, or pause
        self.fly(telemetry, (deck[0], deck[1], bottom), self.ground_feed(track), max_descent=DESCENT_SPEED)
        return self.no_progress(lambda: f"descending onto the deck of {self.target} ({above:.1f} m above it, "
                                f"{off:.1f} m off)", above, off)


class TakeOffFromMovingPlatform(TakeOff):
    """TAKE_OFF_FROM_MOVING_PLATFORM: climb off the platform's deck to the default altitude above it (the drone
    leaves the deck carrying the platform's speed, brakes and holds where it took off)."""

    behavior = "TAKE_OFF_FROM_MOVING_PLATFORM"


class TouchMovingObject(TargetBehavior):
    """TOUCH_MOVING_OBJECT: fly above IMAGE (the nearest object in view without it) at the current altitude,
    descend onto it matching its motion until touching it, then climb straight back to that altitude;
    achieved back up."""

    behavior = "TOUCH_MOVING_OBJECT"
    wanted = "an object to touch"

    def start(self, telemetry: Telemetry) -> None:
        self.altitude = telemetry.altitude
        self.phase = "approach"
        self.touched_at: Vector | None = None

    def find(self, store: TrackStore, telemetry: Telemetry) -> str | None:
        objects = [store.tracks[n] for n in store.seen_now if store.tracks[n].kind == "object"]
        if not objects:
            return None
        return min(objects, key=lambda o: math.dist(o.position, telemetry.position)).name

    def step(self, telemetry: Telemetry) -> Outcome | None:
        if self.phase != "climb":
            return super().step(telemetry)
        assert self.touched_at is not None
        point = (self.touched_at[0], self.touched_at[1], self.altitude)
        self.fly(telemetry, point)
        error = abs(telemetry.altitude - self.altitude)
        if error <= self.settings.hover_altitude_tolerance and telemetry.speed < ARRIVAL_SPEED:
            return Outcome.GOAL_ACHIEVED
        return self.no_progress(lambda: f"climbing back to {self.altitude:.1f} m", error)

    def servo(self, telemetry: Telemetry, track: Track) -> Outcome | None:
        target = track.predict(self.now())
        off = _horizontal(telemetry.position, target)
        if self.phase == "approach":
            yaw = heading_to(telemetry.position, target) if off > FACE_DISTANCE else None
            self.fly(telemetry, (target[0], target[1], self.altitude), self.ground_feed(track), yaw=yaw)
            if off <= self.settings.position_tolerance and self.relative_speed(telemetry, track) < MATCHED_SPEED:
                self.phase = "descend"
                self.progress.reset(self.now())
            return self.no_progress(lambda: f"approaching {self.target} ({off:.1f} m off)", off)
        reach = math.dist(telemetry.position, target)
        if reach <= TOUCH_REACH:
            self.phase, self.touched_at = "climb", telemetry.position
            self.result = self.target
            logger.info("%s: touched %s at %s", self.name, self.target, fmt_point(target))
            self.progress.reset(self.now())
            return None
        bottom = target[2] + TOUCH_HEIGHT if off <= DESCEND_PAUSE else telemetry.altitude
        self.fly(telemetry, (target[0], target[1], bottom), self.ground_feed(track), max_descent=DESCENT_SPEED)
        return self.no_progress(lambda: f"reaching for {self.target} ({reach:.1f} m away)", reach)


TARGET_BEHAVIORS: list[type[BehaviorProcess]] = [
    FollowObjectImage, TrackObjectImage, AlignOverImage, LandOnMovingPlatform, TakeOffFromMovingPlatform,
    TouchMovingObject,
]

__all__ = ["TARGET_BEHAVIORS", "TARGET_PROCESSES", "AlignOverImage", "FollowObjectImage", "LandOnMovingPlatform",
           "TakeOffFromMovingPlatform", "TouchMovingObject", "TrackObjectImage"]
