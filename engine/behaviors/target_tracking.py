"""Visual tracking of targets for the motion-with-targets behaviors: the latest estimate (position, velocity, when
last seen) of everything the drone's cameras see, and the capability processes ``object_tracker`` (VISUAL_SERVOING)
and ``platform_detector`` (HELIPAD_RECOGNITION) that publish what they track as beliefs.

The estimates live in a :class:`TrackStore` kept on the behavior context (:func:`target_tracks`), shared by the
processes and the behaviors; it is updated at most once per engine time from ``drone.observations()`` (visual
servoing: only what the cameras see now). While ``object_tracker`` runs, each target a behavior follows gives
``position(X, (x, y, z))`` and ``visible(X)`` (retracted when X leaves the view); ``platform_detector`` gives
``object(X, platform)``, ``position`` and ``visible`` for a landing platform in view. The capability's
``visual_servoing_controller`` runs idle: the behaviors compute their velocity setpoints themselves.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

from aeroexec.beliefs import Struct
from aeroexec.drones import Observation, Vector
from aeroexec.engine.behaviors.perception import Recognizer
from aeroexec.engine.execution.process import BehaviorContext

VELOCITY_SMOOTHING = 0.3  # weight of a new finite-difference velocity in the estimate
STALE_AFTER = 1.0  # s: a sighting older than this gives no velocity (the target is taken afresh)
PLATFORM_SHAPE = "platform"  # what the camera reports as the shape of a landing platform
_STORE_ATTRIBUTE = "target_tracks"


@dataclass
class Track:
    """The estimate of one thing the cameras saw: where, how fast, and when it was last seen."""

    name: str
    kind: str
    shape: str | None
    position: Vector
    velocity: Vector
    seen_at: float

    def predict(self, now: float) -> Vector:
        """Where the thing should be at ``now`` if it kept its velocity since it was last seen."""
        dt = max(now - self.seen_at, 0.0)
        return (self.position[0] + self.velocity[0] * dt, self.position[1] + self.velocity[1] * dt,
                self.position[2] + self.velocity[2] * dt)

    @property
    def ground_speed(self) -> float:
        return math.hypot(self.velocity[0], self.velocity[1])


class TrackStore:
    """Tracks by name, updated from camera observations; ``wanted`` counts the targets behaviors follow."""

    def __init__(self) -> None:
        self.tracks: dict[str, Track] = {}
        self.wanted: Counter[str] = Counter()
        self.updated_at: float | None = None
        self.seen_now: set[str] = set()

    def update(self, now: float, observations: Iterable[Observation]) -> None:
        """Take in what the cameras see at ``now`` (once per time: later calls at the same time do nothing)."""
        if self.updated_at is not None and now <= self.updated_at + 1e-9:
            return
        self.updated_at = now
        self.seen_now = set()
        for o in observations:
            self.seen_now.add(o.name)
            previous = self.tracks.get(o.name)
            velocity: Vector = (0.0, 0.0, 0.0)
            if previous is not None and 1e-6 < now - previous.seen_at <= STALE_AFTER:
                dt = now - previous.seen_at
                measured = tuple((p - q) / dt for p, q in zip(o.position, previous.position, strict=True))
                velocity = tuple(v + VELOCITY_SMOOTHING * (m - v)  # type: ignore[assignment]
                                 for v, m in zip(previous.velocity, measured, strict=True))
            self.tracks[o.name] = Track(o.name, o.kind, o.shape, tuple(o.position), velocity, now)  # type: ignore[arg-type]

    def get(self, name: str) -> Track | None:
        return self.tracks.get(name)

    def platforms(self) -> list[Track]:
        """The landing platforms seen at the last update."""
        return [t for t in self.tracks.values() if t.shape == PLATFORM_SHAPE and t.name in self.seen_now]

    def want(self, name: str) -> None:
        """A behavior follows ``name`` (its position and visibility become beliefs while object_tracker runs)."""
        self.wanted[name] += 1

    def unwant(self, name: str) -> None:
        self.wanted[name] -= 1
        if self.wanted[name] <= 0:
            del self.wanted[name]


def target_tracks(context: BehaviorContext) -> TrackStore:
    """The run's target estimates, created on first use and kept on the behavior context."""
    return vars(context).setdefault(_STORE_ATTRIBUTE, TrackStore())


def observe(context: BehaviorContext, now: float) -> TrackStore:
    """The run's target estimates brought up to ``now`` from the drone's cameras."""
    store = target_tracks(context)
    store.update(now, context.drone.observations())
    return store


class ObjectTracker(Recognizer):
    """object_tracker: keeps the target estimates current every tick and publishes the followed targets as
    ``position(X, P)`` and ``visible(X)`` beliefs every :data:`~.perception.PERIOD` seconds."""

    def step(self, now: float) -> None:
        observe(self.context, now)
        super().step(now)

    def recognizes(self, observation: Observation) -> bool:
        return observation.name in target_tracks(self.context).wanted

    def beliefs(self, observation: Observation) -> list[Struct]:
        return []


class PlatformDetector(Recognizer):
    """platform_detector: a landing platform in view gives ``object(X, platform)``, ``position`` and ``visible``."""

    def recognizes(self, observation: Observation) -> bool:
        return observation.kind == "object" and observation.shape == PLATFORM_SHAPE

    def beliefs(self, observation: Observation) -> list[Struct]:
        return [Struct("object", (observation.name, PLATFORM_SHAPE))]


TARGET_PROCESSES = {"object_tracker": ObjectTracker, "platform_detector": PlatformDetector}
