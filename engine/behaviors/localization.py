"""Self-localization (paper Table A.3, Appendix B): where the robot believes it is, and the processes that estimate it.

SELF_LOCALIZE_BY_ODOMETRY, SELF_LOCALIZE_BY_VISUAL_MARKERS and SLAM_BY_VISUAL_MARKERS (recurrent, mutually
incompatible) set the localization mode, believed as ``localization(self, odometry|visual_markers|slam)``.
While a mode is set, ``position(self, (x, y, z))`` holds the estimate of these capability processes instead of
the telemetry (the engine's :class:`~aeroexec.engine.execution.updaters.PositionSource` says who writes it):

- ``odometry_state_estimator`` integrates the telemetry velocity with a seeded drift (a bias plus a random walk,
  a few cm per meter travelled), so the belief drifts from the truth as the drone flies; on a real vehicle
  (``Drone.estimates_position``: MAVSDK) it believes the autopilot's own estimate, whose drift is real;
- ``marker_localizer`` pulls the estimate toward the fixes given by the markers in view whose position is
  known: the world's markers (``context.obstacles.markers``) or else the believed ``position(marker_N, P)``;
  under SLAM, the map the SLAM built;
- ``obstacle_distance_calculator`` (SLAM) maps each marker the first time it is seen, at the estimate plus
  the camera's offset, and believes ``position(marker_N, P)`` when nothing was believed of it yet.

The motion behaviors keep flying on the telemetry (the autopilot's own estimate); these beliefs are what the
robot believes. Markers on the world's moving platform are never used as landmarks.

Settings read from ``EngineSettings.extra``: ``odometry_seed`` (0), ``odometry_drift`` (bias, m per m
travelled, 0.03), ``odometry_noise`` (random walk, m per square root of m travelled, 0.01), ``marker_noise``
(fix error, m per m of range, 0.002) and ``marker_gain`` (share of the fix error corrected per look, 0.6).
"""

from __future__ import annotations

import logging
import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field

from aeroexec.beliefs import Struct
from aeroexec.drones import Observation
from aeroexec.engine.execution.process import BehaviorContext, BehaviorProcess, EngineSettings
from aeroexec.engine.execution.resources import Process

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, ClassVar

logger = logging.getLogger(__name__)

Vector = tuple[float, float, float]

OWNER = "self_localization"  # the name under which the estimate claims position(self)
NORMAL_PAIRS = 64  # pairs of the odometry's normal draws made at once
_TWO_PI = 2.0 * math.pi  # random.TWOPI
PUBLISH_PERIOD = 0.1  # s between two beliefs of the estimate
LOOK_PERIOD = 0.2  # s between two looks at the markers in view
_STATE_ATTRIBUTE = "localization_state"


@dataclass
class LocalizationState:
    """The run's self-localization: the mode, the estimate, the distance travelled and the SLAM map."""

    mode: str | None = None  # odometry, visual_markers, slam; None: position(self) comes from the telemetry
    estimate: Vector | None = None
    travelled: float = 0.0  # m flown since the estimator started
    landmarks: dict[str, Vector] = field(default_factory=dict)  # the SLAM map: marker name -> position


def localization_state(context: BehaviorContext) -> LocalizationState:
    """The run's localization state, created on first use and kept on the behavior context."""
    state = getattr(context, _STATE_ATTRIBUTE, None)
    if state is None:
        state = LocalizationState()
        setattr(context, _STATE_ATTRIBUTE, state)
    return state


def publish(context: BehaviorContext, state: LocalizationState | None = None) -> None:
    """Believe the estimate as ``position(self, ...)`` when a localization mode is set (claiming the belief);
    ``state``: the run's :func:`localization_state`, when the caller holds it (the odometry, every other period)."""
    if state is None:
        state = localization_state(context)
    estimate = state.estimate
    if state.mode is None or estimate is None:
        return
    source = context.position_source
    if source is not None and source.owner != OWNER:
        source.claim(OWNER)
    x, y, z = estimate
    context.memory.add(Struct("position", ("self", (round(x, 2), round(y, 2), round(z, 2)))))


def _setting(settings: EngineSettings, key: str, default: float) -> float:
    return float(settings.extra.get(key, default))


def _add(a: Vector, b: Vector, scale: float = 1.0) -> Vector:
    return (a[0] + scale * b[0], a[1] + scale * b[1], a[2] + scale * b[2])


def _sub(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def normal_draws(rng: random.Random, pairs: int) -> list[float]:
    """The next ``2 * pairs`` values of ``rng.gauss(0.0, 1.0)``, the same numbers in the same order (and ``rng`` left
    as that many calls leave it, its ``gauss_next`` empty), made together: ``random.gauss``'s own Box-Muller pairs,
    without a call per value. ``rng.gauss_next`` must be empty (its first value is the pair's second)."""
    if rng.gauss_next is not None:  # type: ignore[attr-defined]
        raise ValueError("normal_draws: the generator holds half a pair (gauss_next): draw it with gauss first")
    uniform, out = rng.random, []
    append = out.append
    for _ in range(pairs):
        x2pi = uniform() * _TWO_PI
        g2rad = math.sqrt(-2.0 * math.log(1.0 - uniform()))
        append(0.0 + math.cos(x2pi) * g2rad)  # mu + z * sigma, with mu 0.0 and sigma 1.0 (z * 1.0 is z)
        append(0.0 + math.sin(x2pi) * g2rad)
    return out


def _platform_markers(context: BehaviorContext) -> set[str]:
    """Names of the markers on the world's moving platform (never landmarks)."""
    platform = getattr(context.obstacles, "platform", None)
    marker_id = getattr(platform, "marker_id", None)
    return set() if marker_id is None else {f"marker_{marker_id}"}


class OdometryEstimator(Process):
    """odometry_state_estimator: dead reckoning on the telemetry velocity, with a seeded bias and random walk; on a
    vehicle that estimates its own position (a real autopilot: ``Drone.estimates_position``), that estimate, as it
    is: the drift is the simulator's."""

    def on_start(self) -> None:
        self.follows = bool(getattr(self.context.drone, "estimates_position", True))
        self._state = localization_state(self.context)  # kept on the context for the run: looked up once
        self._telemetry = self.context.drone.telemetry
        if self.follows:
            localization_state(self.context).estimate = tuple(float(v) for v in self.context.drone.telemetry().position)
            self._published: float | None = None
            return
        settings = self.context.settings
        self._rng = random.Random(int(settings.extra.get("odometry_seed", 0)))
        drift = _setting(settings, "odometry_drift", 0.03)
        self._noise = _setting(settings, "odometry_noise", 0.01)
        heading, climb = self._rng.uniform(0.0, 2 * math.pi), self._rng.uniform(-0.25, 0.25)
        self._bias = (drift * math.cos(heading), drift * math.sin(heading), drift * climb)
        telemetry = self.context.drone.telemetry()
        state = localization_state(self.context)
        if state.estimate is None:
            state.estimate = tuple(float(v) for v in telemetry.position)
        self._last: tuple[float, Vector] | None = None
        self._published: float | None = None
        self._normal: list[float] = []  # the random walk's draws of self._rng.gauss(0.0, 1.0), made ahead in pairs
        self._drawn = 0  # how many of them were used

    def step(self, now: float) -> None:
        state = self._state
        if self.follows:  # the autopilot's own estimate (GPS and its EKF), not dead reckoning on it
            telemetry = self._telemetry()
            state.travelled += math.dist(telemetry.position, state.estimate) if state.estimate else 0.0
            state.estimate = tuple(float(v) for v in telemetry.position)
            if self._published is None or now - self._published >= PUBLISH_PERIOD - 1e-9:
                self._published = now
                publish(self.context, state)
            return
        vx, vy, vz = self._telemetry().velocity
        velocity = (float(vx), float(vy), float(vz))
        last = self._last
        if last is not None and now > last[0]:
            dt = now - last[0]
            (lx, ly, lz) = last[1]
            mx, my, mz = (vx + lx) / 2 * dt, (vy + ly) / 2 * dt, (vz + lz) / 2 * dt  # moved
            travelled = math.hypot(mx, my, mz)
            if travelled > 1e-6:
                normal, k = self._normal, self._drawn
                if k + 3 > len(normal):  # three draws of self._rng.gauss(0.0, 1.0) a step, in the order they came
                    normal = self._normal = normal[k:] + normal_draws(self._rng, NORMAL_PAIRS)
                    k = 0
                self._drawn = k + 3
                bx, by, bz = self._bias
                step = self._noise * math.sqrt(travelled)
                ex, ey, ez = state.estimate  # + moved + error, as _add(_add(estimate, moved), error)
                state.estimate = (ex + mx + (bx * travelled + step * normal[k]),
                                  ey + my + (by * travelled + step * normal[k + 1]),
                                  ez + mz + (bz * travelled + step * normal[k + 2] * 0.5))
                state.travelled += travelled
        self._last = (now, velocity)
        published = self._published
        if published is None or now - published >= PUBLISH_PERIOD - 1e-9:
            self._published = now
            publish(self.context, state)

    def on_stop(self) -> None:
        if self.context.position_source is not None:
            self.context.position_source.release(OWNER)


class MarkerLook(Process):
    """A process that looks at the markers in view every :data:`LOOK_PERIOD` while a marker mode is set."""

    modes: ClassVar[tuple[str, ...]] = ("visual_markers", "slam")

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self._looked: float | None = None
        self._rng = random.Random(0)

    def on_start(self) -> None:
        seed = int(self.context.settings.extra.get("odometry_seed", 0))
        self._rng = random.Random(seed * 1000 + sum(map(ord, self.name)))

    def step(self, now: float) -> None:
        if self._looked is not None and now - self._looked < LOOK_PERIOD - 1e-9:
            return
        self._looked = now
        state = localization_state(self.context)
        if state.mode not in self.modes or state.estimate is None:
            return
        truth = self.context.drone.telemetry().position
        skip = _platform_markers(self.context)
        seen = [o for o in self.context.drone.observations()
                if o.kind == "marker" and o.name not in skip]
        if seen:
            self.look(state, seen, truth)

    def offset(self, observation: Observation, truth: Vector) -> Vector:
        """Where the camera measures the marker from the drone (with a range-proportional error)."""
        sigma = max(_setting(self.context.settings, "marker_noise", 0.002) * observation.distance, 1e-4)
        return tuple(p - t + self._rng.gauss(0.0, sigma)
                     for p, t in zip(observation.position, truth, strict=True))  # type: ignore[return-value]

    def look(self, state: LocalizationState, seen: list[Observation], truth: Vector) -> None:
        """Use the markers in view (visible now, never on the moving platform)."""


class MarkerLocalizer(MarkerLook):
    """marker_localizer: corrects the estimate with the fixes of the markers in view whose position is known."""

    def known_map(self, state: LocalizationState) -> dict[str, Vector]:
        if state.mode == "slam":
            return state.landmarks
        markers = getattr(self.context.obstacles, "markers", None)
        if markers is not None:
            return {m.name: tuple(m.position) for m in markers}
        found = self.context.memory.query_all("object(?M, marker), position(?M, (?X, ?Y, ?Z))")
        return {str(f["?M"]): (float(f["?X"]), float(f["?Y"]), float(f["?Z"])) for f in found}

    def look(self, state: LocalizationState, seen: list[Observation], truth: Vector) -> None:
        known = self.known_map(state)
        fixes = [(o.name, _sub(known[o.name], self.offset(o, truth))) for o in seen if o.name in known]
        if not fixes:
            return
        fix = tuple(sum(f[1][i] for f in fixes) / len(fixes) for i in range(3))
        error = _sub(fix, state.estimate)
        gain = _setting(self.context.settings, "marker_gain", 0.6)
        state.estimate = _add(state.estimate, error, gain)
        size = math.hypot(*error)
        if size > 0.1:
            names = ", ".join(name for name, _ in fixes)
            self.context.log.record("localization_corrected", detail=f"{gain * size:.2f} m toward the fix of {names}",
                                    error=round(size, 3), markers=[name for name, _ in fixes])
        publish(self.context)


class SlamMapper(MarkerLook):
    """obstacle_distance_calculator (SLAM): maps each marker when first seen, at the estimate plus its offset."""

    modes = ("slam",)

    def look(self, state: LocalizationState, seen: list[Observation], truth: Vector) -> None:
        memory = self.context.memory
        for observation in seen:
            if observation.name in state.landmarks:
                continue
            point = _add(state.estimate, self.offset(observation, truth))
            state.landmarks[observation.name] = point
            where = tuple(round(v, 2) for v in point)
            if not memory.holds(f"position({observation.name}, ?P)"):
                memory.add(Struct("position", (observation.name, where)))
            memory.add(Struct("object", (observation.name, "marker")))
            if observation.marker_id is not None:
                memory.add(Struct("code", (observation.name, observation.marker_id)))
            self.context.log.record("marker_mapped", detail=f"{observation.name} at {list(where)}",
                                    marker=observation.name, position=list(where))


class SelfLocalization(BehaviorProcess):
    """A recurrent behavior that sets the localization mode while it is active; its processes estimate."""

    mode: ClassVar[str] = ""

    def on_start(self) -> None:
        state = localization_state(self.context)
        state.mode = self.mode
        if state.estimate is None:  # no estimator has run yet: start from the telemetry
            state.estimate = tuple(float(v) for v in self.telemetry().position)
        self.memory.add(Struct("localization", ("self", self.mode)))
        publish(self.context)

    def on_stop(self, outcome: Any) -> None:
        state = localization_state(self.context)
        if state.mode != self.mode:
            return
        state.mode = None
        if self.context.position_source is not None:
            self.context.position_source.release(OWNER)
        self.memory.remove(Struct("localization", ("self", self.mode)))


class SelfLocalizeByOdometry(SelfLocalization):
    behavior = "SELF_LOCALIZE_BY_ODOMETRY"
    mode = "odometry"


class SelfLocalizeByVisualMarkers(SelfLocalization):
    behavior = "SELF_LOCALIZE_BY_VISUAL_MARKERS"
    mode = "visual_markers"


class SlamByVisualMarkers(SelfLocalization):
    behavior = "SLAM_BY_VISUAL_MARKERS"
    mode = "slam"


LOCALIZATION_BEHAVIORS: list[type[BehaviorProcess]] = [SelfLocalizeByOdometry, SelfLocalizeByVisualMarkers,
                                                       SlamByVisualMarkers]
LOCALIZATION_PROCESSES: dict[str, Callable[[str], Process]] = {"odometry_state_estimator": OdometryEstimator,
                                                               "marker_localizer": MarkerLocalizer,
                                                               "obstacle_distance_calculator": SlamMapper}
