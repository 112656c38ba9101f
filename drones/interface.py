"""The drone interface: the commands and telemetry every drone implementation serves.

The engine talks to one :class:`Drone`. Two implementations serve it: the
simulated drone (``aeroexec.drones.sim``, in-process on the engine's clock) and
the MAVSDK adapter (``aeroexec.drones.mavsdk``). Commands never block the
engine's tick: each returns a :class:`CommandHandle` that completes when the
vehicle accepts or refuses the command (not when the manoeuvre ends: behaviors
watch the telemetry for that).

Frames: positions and velocities are local ENU meters from the home point
(x east, y north, z up); yaw is in degrees, 0 = east (x), counterclockwise
positive, in (-180, 180] (ROS REP 103).
"""

from __future__ import annotations

import abc
import enum
import threading
from dataclasses import dataclass, field, fields

Vector = tuple[float, float, float]
#: Where a robot's photos come from (:meth:`Robot.photo_source`).
CAMERA_IMAGES, CAMERA_VEHICLE, CAMERA_NONE = "images", "vehicle", "none"


class LandedState(enum.Enum):
    """Where the vehicle is in its flight, as autopilots report it."""

    UNKNOWN = "unknown"
    ON_GROUND = "on_ground"
    TAKING_OFF = "taking_off"
    IN_AIR = "in_air"
    LANDING = "landing"


class Failure(enum.Enum):
    """Why a command failed."""

    DENIED = "denied"  # the vehicle refused it (not armable, wrong state, out of bounds...)
    TIMEOUT = "timeout"  # no answer in time
    LINK_LOST = "link_lost"  # the link to the vehicle is down
    UNSUPPORTED = "unsupported"  # this vehicle cannot do it
    CANCELLED = "cancelled"  # superseded or the drone was closed


@dataclass(frozen=True, slots=True)
class Telemetry:
    """A snapshot of the vehicle's state, readable at any time without blocking."""

    time: float = 0.0  # seconds on the clock of the drone's owner when sampled
    position: Vector = (0.0, 0.0, 0.0)  # ENU meters from home
    velocity: Vector = (0.0, 0.0, 0.0)  # ENU m/s
    yaw: float = 0.0  # degrees, 0 = east, counterclockwise positive
    battery_percent: float = 100.0  # 0..100
    battery_voltage: float = 16.8  # volts
    armed: bool = False
    landed_state: LandedState = LandedState.UNKNOWN
    flight_mode: str = "UNKNOWN"  # e.g. HOLD, TAKEOFF, LAND, OFFBOARD, RETURN, MANUAL
    link_ok: bool = True  # False once the link has been silent for too long
    home: tuple[float, float, float] | None = None  # latitude, longitude, altitude (m AMSL)
    wind: tuple[float, float] | None = None  # m/s east, north: the wind the vehicle estimates (None: not known)
    ground_link: bool | None = None  # the link to the ground station, when the engine flies on board (None: link_ok)
    position_accuracy: float | None = None  # m, horizontal, of the vehicle's own estimate (None: unknown or exact)
    position_time: float | None = None  # when the position came from the vehicle, on the same clock (None: at time)

    @property
    def altitude(self) -> float:
        return self.position[2]

    @property
    def speed(self) -> float:
        vx, vy, vz = self.velocity
        return (vx * vx + vy * vy + vz * vz) ** 0.5


_TELEMETRY_FIELDS = ("time", "position", "velocity", "yaw", "battery_percent", "battery_voltage", "armed",
                     "landed_state", "flight_mode", "link_ok", "home", "wind", "ground_link", "position_accuracy",
                     "position_time")
if tuple(f.name for f in fields(Telemetry)) != _TELEMETRY_FIELDS:  # pragma: no cover (a field added above)
    raise AssertionError("telemetry_snapshot fills Telemetry's fields in their order: name every one")
(_TIME, _POSITION, _VELOCITY, _YAW, _PERCENT, _VOLTAGE, _ARMED, _LANDED, _MODE, _LINK, _HOME, _WIND, _GROUND,
 _ACCURACY, _POSITION_TIME) = (getattr(Telemetry, name).__set__ for name in _TELEMETRY_FIELDS)


def telemetry_snapshot(time: float, position: Vector, velocity: Vector, yaw: float, battery_percent: float,
                       battery_voltage: float, armed: bool, landed_state: LandedState, flight_mode: str,
                       link_ok: bool = True, home: tuple[float, float, float] | None = None,
                       wind: tuple[float, float] | None = None, ground_link: bool | None = None,
                       position_accuracy: float | None = None, position_time: float | None = None) -> Telemetry:
    """``Telemetry(...)`` of these fields, made by filling its slots: the frozen dataclass's ``__init__`` sets each of
    its 15 fields through ``object.__setattr__`` (~2.8 µs; this ~1.3 µs), and a simulated drone makes one every
    engine period."""
    t = object.__new__(Telemetry)
    _TIME(t, time)
    _POSITION(t, position)
    _VELOCITY(t, velocity)
    _YAW(t, yaw)
    _PERCENT(t, battery_percent)
    _VOLTAGE(t, battery_voltage)
    _ARMED(t, armed)
    _LANDED(t, landed_state)
    _MODE(t, flight_mode)
    _LINK(t, link_ok)
    _HOME(t, home)
    _WIND(t, wind)
    _GROUND(t, ground_link)
    _ACCURACY(t, position_accuracy)
    _POSITION_TIME(t, position_time)
    return t


class CommandHandle:
    """The pending outcome of a command; completed once, from any thread.

    Poll ``done`` from the engine's tick; ``wait`` is for tests and scripts.
    """

    __slots__ = ("command", "_event", "_failure", "_reason")

    def __init__(self, command: str) -> None:
        self.command = command
        self._event = threading.Event()
        self._failure: Failure | None = None
        self._reason = ""

    @classmethod
    def succeeded(cls, command: str) -> CommandHandle:
        handle = cls(command)
        handle.succeed()
        return handle

    @classmethod
    def failed(cls, command: str, failure: Failure, reason: str) -> CommandHandle:
        handle = cls(command)
        handle.fail(failure, reason)
        return handle

    def succeed(self) -> None:
        if not self._event.is_set():
            self._event.set()

    def fail(self, failure: Failure, reason: str) -> None:
        if not self._event.is_set():
            self._failure = failure
            self._reason = reason
            self._event.set()

    @property
    def done(self) -> bool:
        return self._event.is_set()

    @property
    def ok(self) -> bool:
        """True when done and accepted."""
        return self._event.is_set() and self._failure is None

    @property
    def failure(self) -> Failure | None:
        return self._failure

    @property
    def reason(self) -> str:
        """A sentence for the operator when the command failed, e.g. "arming denied: ..."."""
        return self._reason

    def wait(self, timeout: float) -> bool:
        """Block until done or ``timeout`` seconds; True when done. Never call from a tick."""
        return self._event.wait(timeout)

    def __repr__(self) -> str:
        state = "pending" if not self.done else ("ok" if self.ok else f"{self._failure.value}: {self._reason}")
        return f"<{self.command} {state}>"


@dataclass(frozen=True, slots=True)
class Observation:
    """Something the drone's camera sees now (simulated drones; empty elsewhere)."""

    kind: str  # "marker" or "object"
    name: str  # e.g. "marker_3", "red_box"
    position: Vector  # ENU meters
    marker_id: int | None = None  # ArUco id for markers
    color: str | None = None
    shape: str | None = None
    distance: float = 0.0


@dataclass(frozen=True, slots=True)
class DroneEvent:
    """Something that happened to the vehicle that the engine must hear of."""

    time: float
    kind: str  # "collision", "failsafe", "link_lost", "link_restored", "out_of_bounds", ...
    detail: str = ""
    data: dict = field(default_factory=dict)


class Robot(abc.ABC):
    """What the engine needs from any robot: time, its own state, what it perceives, and a way to stop.

    Implementations must never block in these calls. A drone is one kind of robot (:class:`Drone`); a robot of
    another kind adds the commands its own behaviors use.
    """

    @abc.abstractmethod
    def update(self, now: float) -> None:
        """Called by the engine on every tick with its clock's time.

        A simulated robot integrates its motion up to ``now``; a real robot's adapter
        only refreshes its view (its I/O runs elsewhere).
        """

    @abc.abstractmethod
    def telemetry(self) -> Telemetry:
        """The latest state, without blocking."""

    @abc.abstractmethod
    def hold(self) -> CommandHandle:
        """Stop where the robot is (a drone hovers)."""

    def capture_image(self) -> bytes | None:
        """A PNG of what the camera sees now, or None when this robot has no camera it can read."""
        return None

    def photo_source(self) -> str:
        """Where this robot's photos come from: :data:`CAMERA_IMAGES` (the engine saves :meth:`capture_image`'s
        image: the simulator), :data:`CAMERA_VEHICLE` (the vehicle's own camera takes them: :meth:`take_photo`), or
        :data:`CAMERA_NONE` (the vehicle has none: a photo is skipped, said in the event log)."""
        return CAMERA_IMAGES

    def take_photo(self) -> CommandHandle:
        """A photo by the vehicle's own camera (when :meth:`photo_source` is :data:`CAMERA_VEHICLE`): the handle
        completes when the camera says it took it."""
        return CommandHandle.failed("take_photo", Failure.UNSUPPORTED, "this robot has no camera of its own")

    def payload(self) -> list[str]:
        """The names of the items the robot carries now; empty when it carries nothing or cannot tell."""
        return []

    def observations(self) -> list[Observation]:
        """What the camera sees now; robots without a simulated camera see nothing."""
        return []

    def events(self) -> list[DroneEvent]:
        """Events since the last call (collisions, failsafes, link changes), oldest first."""
        return []

    def close(self) -> None:  # noqa: B027 - optional: a robot with nothing to release keeps this one
        """Release the robot: stop I/O threads. Must return promptly, never hang."""


class Drone(Robot):
    """What the engine's flight behaviors need from a drone, besides what every robot gives."""

    #: The telemetry's position is the vehicle's own estimate (a real autopilot's, from GPS and its EKF): the
    #: engine's odometry then follows it. False for a simulator, whose position is the truth: the engine's odometry
    #: estimator simulates dead reckoning's drift on top of it.
    estimates_position: bool = True

    @abc.abstractmethod
    def arm(self) -> CommandHandle: ...

    @abc.abstractmethod
    def disarm(self) -> CommandHandle: ...

    @abc.abstractmethod
    def takeoff(self, altitude: float) -> CommandHandle:
        """Climb vertically to ``altitude`` meters above home (arms first if the vehicle needs it)."""

    @abc.abstractmethod
    def land(self) -> CommandHandle: ...

    @abc.abstractmethod
    def goto(self, position: Vector, yaw: float | None = None, speed: float | None = None) -> CommandHandle:
        """Fly to a local ENU point; ``yaw`` in degrees at arrival; ``speed`` in m/s (vehicle default if None)."""

    @abc.abstractmethod
    def set_velocity(self, velocity: Vector, yaw_rate: float = 0.0) -> CommandHandle:
        """Fly at an ENU velocity (m/s) and yaw rate (deg/s, counterclockwise) until told otherwise."""

    @abc.abstractmethod
    def hold(self) -> CommandHandle:
        """Stop and hover where the vehicle is."""

    @abc.abstractmethod
    def return_to_launch(self) -> CommandHandle: ...

    def release_payload(self) -> CommandHandle:
        """Open the payload release (drop what the drone carries)."""
        return CommandHandle.failed("release_payload", Failure.UNSUPPORTED, "this drone has no payload release")
