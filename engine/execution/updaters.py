"""The engine's belief updaters: the drone's own state from telemetry, and the predicates computed when consulted.

:class:`TelemetryUpdater` writes ``position(self, (x, y, z))`` (and ``position_accuracy(self, M)`` when the vehicle
says how good its own estimate is), ``flight_state``,
``charge(battery, N)``, ``battery_level``, ``armed``, ``orientation``, ``speed``,
``flight_mode``, ``communication(wireless, ok|lost)`` and ``carry(self, X)`` for
each item the drone says it carries; :func:`register_computed`
answers ``distance``, ``distance_to``, ``approximate_travel_time``, ``flight_time_left`` and the
obstacle distances from functions. A :class:`PositionSource` says whether the
telemetry or a self-localization estimator writes ``position(self, ...)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from aeroexec.beliefs import BeliefMemory, BeliefUpdater, Struct
from aeroexec.drones import Drone, LandedState, Telemetry

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, Protocol
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

MOVING_ABOVE = 0.5  # m/s: faster is moving
HOVERING_BELOW = 0.25  # m/s: slower is hovering (in between, the state does not change)


class ObstacleMap(Protocol):
    """What the engine knows of obstacles: the simulated world, or a map an embedding robot provides."""

    def distance_to_obstacle(self, point: tuple[float, float, float]) -> float: ...


def flight_state(telemetry: Telemetry, previous: str | None) -> str:
    """The qualitative flight state: landed, taking_off, hovering, moving or landing."""
    landed = telemetry.landed_state
    if landed is LandedState.ON_GROUND or (landed is LandedState.UNKNOWN and not telemetry.armed):
        return "landed"
    if landed is LandedState.TAKING_OFF:
        return "taking_off"
    if landed is LandedState.LANDING:
        return "landing"
    speed = telemetry.speed
    if speed > MOVING_ABOVE:
        return "moving"
    if speed < HOVERING_BELOW or previous not in ("moving", "hovering"):
        return "hovering"
    return previous


def battery_level(percent: float) -> str:
    return "low" if percent < 20 else "medium" if percent < 50 else "high"


#: The predicates the telemetry updater writes, declared by the engine when a catalog does not.
TELEMETRY_PREDICATES = {"position": 2, "flight_state": 2, "charge": 2, "battery_level": 2, "armed": 2,
                        "orientation": 2, "speed": 2, "flight_mode": 2, "communication": 2, "position_accuracy": 2,
                        "wind": 2}
#: The first argument of each belief the telemetry updater writes (the second is the value it reads)
SUBJECTS = {name: "self" for name in TELEMETRY_PREDICATES} | {"charge": "battery", "communication": "wireless"}
_UNWRITTEN = object()  # the value of a belief not written (or retracted since): never equal to a value read


class PositionSource:
    """Who writes ``position(self, ...)``: the telemetry updater, unless a state estimator process has claimed it."""

    def __init__(self) -> None:
        self.owner: str | None = None  # the claiming process's name; None: the telemetry writes it

    def claim(self, owner: str) -> None:
        self.owner = owner

    def release(self, owner: str) -> None:
        if self.owner == owner:
            self.owner = None

    @property
    def from_telemetry(self) -> bool:
        return self.owner is None


class TelemetryUpdater(BeliefUpdater):
    """Beliefs about the robot itself, from the drone's telemetry snapshot.

    ``position(self, ...)`` is left to the estimator that claimed :attr:`position_source`, if any.
    """

    def __init__(self, drone: Drone, period: float = 0.1, position_source: PositionSource | None = None) -> None:
        super().__init__("telemetry", period)
        self.drone = drone
        self.position_source = position_source or PositionSource()
        self._state: str | None = None
        self._carried: set[str] = set()  # the items the drone said it carries, as believed
        self._written: dict[str, Any] = {}  # predicate -> the value last believed (and still believed)
        self._memory: BeliefMemory | None = None

    def update(self, memory: BeliefMemory, now: float) -> None:
        if memory is not self._memory:  # hear removals, so a belief someone retracts is written again
            self._memory, self._written = memory, {}
            memory.subscribe(self._changed, TELEMETRY_PREDICATES)  # of what it writes only
        t = self.drone.telemetry()
        state = self._state = flight_state(t, self._state)
        percent = t.battery_percent
        # Each value is compared with the one last believed before its belief is made: only what changed is written,
        # in this order (a belief with a lifetime is renewed every time).
        values: list[tuple[str, Any]] = [
            ("flight_state", state),
            ("charge", int(math.floor(percent))),
            ("battery_level", battery_level(percent)),
            ("armed", "yes" if t.armed else "no"),
            ("orientation", round(t.yaw)),
            ("speed", round(t.speed, 1)),
            ("flight_mode", t.flight_mode),
            ("communication", "ok" if t.link_ok and t.ground_link is not False else "lost"),
        ]
        if t.wind is not None:  # to half a meter per second: gusts do not rewrite it every update
            values.append(("wind", round(2.0 * math.hypot(*t.wind)) / 2.0))
        if self.position_source.owner is None:  # from_telemetry, without the property's call
            x, y, z = t.position
            values.append(("position", (round(x, 2), round(y, 2), round(z, 2))))
        if t.position_accuracy is not None:  # the vehicle's own estimate says how far off it may be
            values.append(("position_accuracy", round(t.position_accuracy, 1)))
        written, renewed = self._written, memory.lifetimes
        for name, value in values:
            if written.get(name, _UNWRITTEN) != value or name in renewed:
                memory.add(Struct(name, (SUBJECTS[name], value)))
                written[name] = value
        carried = self.drone.payload()  # carry(self, X) follows what the drone says it carries
        if carried or self._carried:
            self._carry(memory, set(carried))

    def _carry(self, memory: BeliefMemory, carried: set[str]) -> None:
        for item in sorted(carried - self._carried):
            memory.add(Struct("carry", ("self", item)))
        for item in sorted(self._carried - carried):
            memory.remove(Struct("carry", ("self", item)))
        self._carried = carried

    def _changed(self, change: Any) -> None:
        """A belief this updater wrote was retracted (by a mission, an operator, an exclusive value): forget it."""
        if change.kind == "removed":
            name, args = change.belief.name, change.belief.args
            if name in self._written and args == (SUBJECTS[name], self._written[name]):
                del self._written[name]


def register_computed(memory: BeliefMemory, drone: Drone, cruise_speed: float,
                      obstacles: ObstacleMap | None = None, flight_time: float | None = None) -> None:
    """Register the predicates answered by functions (Table 7); ``flight_time``: seconds a full battery keeps the
    drone in the air (the catalog's ``vehicle_limits.max_flight_time``; None: unknown, never the limit)."""

    def point(value: Any) -> tuple[float, float, float] | None:  # (written out: safety rules ask it often)
        if isinstance(value, tuple) and len(value) == 3:
            x, y, z = value
            if type(x) is float and type(y) is float and type(z) is float and type(value) is tuple:
                return value
            if isinstance(x, (int, float)) and isinstance(y, (int, float)) and isinstance(z, (int, float)):
                return (float(x), float(y), float(z))
        return None

    def guarded(function: Callable[..., float | None]) -> Callable[..., float | None]:
        def answer(*args: Any) -> float | None:
            points = []
            for a in args:
                found = point(a)
                if found is None:
                    return None
                points.append(found)
            return function(*points)
        return answer

    def travel_time(a: tuple, b: tuple) -> float:
        # a trapezoidal profile at cruise speed with 1 s to accelerate and 1 s to brake
        return round(math.dist(a, b) / cruise_speed + 1.0, 2)

    def to_obstacle(p: tuple) -> float:
        return round(obstacles.distance_to_obstacle(p), 2) if obstacles is not None else math.inf

    memory.register("distance", 3, guarded(lambda a, b: round(math.dist(a, b), 2)))
    memory.register("distance_to", 2, guarded(lambda p: round(math.dist(drone.telemetry().position, p), 2)))
    memory.register("approximate_travel_time", 3, guarded(travel_time))

    def time_left(who: Any) -> float | None:
        if who != "self":
            return None
        if flight_time is None:
            return math.inf
        return round(max(drone.telemetry().battery_percent, 0.0) / 100.0 * flight_time, 1)

    memory.register("flight_time_left", 2, time_left)
    memory.register("minimum_distance_to_obstacle", 2, guarded(to_obstacle))
    memory.register("distance_to_obstacle", 2, guarded(to_obstacle))
