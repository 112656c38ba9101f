"""The built-in simulated drone: the :class:`Drone` interface over a kinematic multicopter in a :class:`World`.

It owns no clock: ``update(now)`` integrates fixed substeps up to ``now``, so the same world, seed and
commands at the same times give the same trajectory. Commands are accepted or refused at once.
"""

from __future__ import annotations

import logging
import math
import random
import threading
from collections.abc import Callable
from functools import wraps

from aeroexec.drones.interface import (
    CAMERA_IMAGES,
    CAMERA_NONE,
    CommandHandle,
    Drone,
    DroneEvent,
    Failure,
    Observation,
    Telemetry,
    Vector,
    telemetry_snapshot,
)
from aeroexec.drones.sim.airspace import Airspace
from aeroexec.drones.sim.camera import Camera, merge_observations
from aeroexec.drones.sim.config import SimConfig
from aeroexec.drones.sim.payload import PayloadBay
from aeroexec.drones.sim.vehicle.multicopter import IDLE, TAKEOFF, Multicopter
from aeroexec.drones.sim.world import World
from aeroexec.drones.sim.world_file import default_world

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import TypeVar

    _F = TypeVar("_F", bound=Callable)

logger = logging.getLogger(__name__)

_FLYING_HEIGHT = 0.3  # m: placed higher than this, a drone said to fly hovers; lower, it stands on the ground

MODES = ("HOLD", "TAKEOFF", "LAND", "RETURN", "OFFBOARD")


def _locked(method: _F) -> _F:
    @wraps(method)
    def wrapper(self: SimulatedDrone, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)

    return wrapper  # type: ignore[return-value]


def _command(method: _F) -> _F:
    """A locked method that may change the vehicle's state: the telemetry read before it is read again."""
    @wraps(method)
    def wrapper(self: SimulatedDrone, *args, **kwargs):
        with self._lock:
            self._telemetry = None
            return method(self, *args, **kwargs)

    return wrapper  # type: ignore[return-value]


def _fmt(point: Vector) -> str:
    return "(" + ", ".join(f"{v:.1f}" for v in point) + ")"


class SimulatedDrone(Drone):
    """A simulated multicopter starting disarmed on the ground at home; thread-safe (one lock)."""

    estimates_position = False  # its position is the truth: odometry drift is simulated on top of it

    def __init__(self, world: World | None = None, *, config: SimConfig | None = None, seed: int = 0,
                 start_time: float = 0.0) -> None:
        self.world = world if world is not None else default_world()
        self.config = config if config is not None else SimConfig()
        self.camera = Camera.from_settings(self.world.camera)
        self.bottom_camera = Camera.downward(self.world.camera)
        self.seed = seed
        self._rng = random.Random(seed)
        self._lock = threading.RLock()
        self._start = start_time
        self._steps = 0
        self._now = start_time
        self._vehicle = Multicopter(self.world, self.config, start_time)
        self._noise: Vector = (0.0, 0.0, 0.0)
        self._observations: list[Observation] | None = None
        self._payload = PayloadBay(self.config.payload if self.config.payload is not None else self.world.payload)
        self._renderer = None  # the camera image renderer, built on the first capture
        self._telemetry: Telemetry | None = None  # the last answer, until an update or a command changes the state
        self.airspace: Airspace | None = None  # the other drones of the world, seen by the cameras
        self.call_sign = ""
        self._gust: tuple[float, float] = (0.0, 0.0)  # m/s: the gusts' part of the wind now
        self._blown = start_time  # when the gusts were last drawn
        self._link_up = True
        self._weather = random.Random(seed + 7919)  # the gusts and dropped detections (apart from the noise)
        # what the (frozen) configuration asks of every period, read once
        self._windy = self.config.wind != (0.0, 0.0) or self.config.wind_gust > 0.0
        self._noisy = self.config.position_noise_std > 0.0

    @_locked
    def place(self, position: Vector, yaw: float = 0.0, *, flying: bool = False,
              battery_percent: float | None = None) -> None:
        """Put the drone at ``position`` before it flies (a resumed run): hovering there armed when ``flying`` (as
        an autopilot holds where its companion computer stopped talking to it), else on the ground under it. Home
        (where it returns to) stays where it started."""
        v = self._vehicle
        x, y, z = (float(c) for c in position)
        v.yaw = float(yaw)
        if battery_percent is not None:
            v.battery.percent = max(0.0, min(100.0, float(battery_percent)))
        if flying and z > _FLYING_HEIGHT:
            v.position = (x, y, z)
            v.arm()
            v.airborne = True
            v._flew_since_armed = True
            v.fly_to(v.position, mode="HOLD")
        else:
            v.position = (x, y, 0.0)
        self._telemetry = None

    def join(self, airspace: Airspace, name: str) -> None:
        """Fly in ``airspace`` as ``name``: the other drones there see this one, and it sees them."""
        airspace.add(name, lambda: self._vehicle.position)
        self.airspace, self.call_sign = airspace, name

    # --- time --------------------------------------------------------------------------------------
    def update(self, now: float) -> None:
        """Integrate fixed substeps up to ``now`` (earlier times are ignored)."""
        with self._lock:  # (every engine period: the lock taken here and the update inline, without a call)
            if now <= self._now:
                return
            self._now = now
            self._telemetry = None
            dt = self.config.substep
            target = math.floor((now - self._start) / dt + 1e-9)
            v = self._vehicle
            self._steps = v.advance(self._start, self._steps, target, dt)
            if v.contacts.riding is not None:  # (ride_deck does nothing off the deck: not called)
                v.ride_deck()  # landed on the moving platform (even disarmed): carried along
            if self._windy:
                self._blow(now)
            if self.config.link_loss is not None and self.link_ok(now) != self._link_up:
                self._link_up = not self._link_up
                if self._link_up:
                    v.emit("ground_link_restored")
                else:
                    v.emit("ground_link_lost", "the simulated ground link dropped", altitude=round(v.position[2], 2),
                           in_air=v.airborne)
            if self._noisy:
                s = self.config.position_noise_std
                self._noise = (self._rng.gauss(0.0, s), self._rng.gauss(0.0, s), self._rng.gauss(0.0, s))
            self._observations = None
            if self._payload.falling:  # (_settle_payload has nothing to settle otherwise: not called)
                self._settle_payload()

    def _blow(self, now: float) -> None:
        """The wind at ``now``: the mean plus gusts that wander about it (an Ornstein-Uhlenbeck process, 5 s)."""
        c = self.config
        if c.wind_gust > 0.0:
            dt = max(now - self._blown, 0.0)
            keep = math.exp(-dt / 5.0)
            spread = c.wind_gust * math.sqrt(max(1.0 - keep * keep, 0.0))
            gx, gy = self._gust
            self._gust = (gx * keep + self._weather.gauss(0.0, spread), gy * keep + self._weather.gauss(0.0, spread))
        self._blown = now
        self._vehicle.wind = (c.wind[0] + self._gust[0], c.wind[1] + self._gust[1])

    def link_ok(self, now: float) -> bool:
        """Whether the link to the ground station is up at ``now`` (the configured drop, if any); the engine flies
        on board, so its commands still reach the vehicle."""
        loss = self.config.link_loss
        return loss is None or not (self._start + loss[0] <= now < self._start + loss[0] + loss[1])

    # --- state -------------------------------------------------------------------------------------
    def telemetry(self) -> Telemetry:
        telemetry = self._telemetry  # asked again before anything moved: the same (immutable) answer, lock-free
        if telemetry is None:
            with self._lock:
                telemetry = self._telemetry
                if telemetry is None:
                    telemetry = self._telemetry = self._read_telemetry(self._vehicle)
        return telemetry

    def _read_telemetry(self, v: Multicopter) -> Telemetry:
        position, yaw = v.carried(self._now)  # the last whole substep's state, carried on to ``time``
        if self._noisy:
            position = tuple(p + n for p, n in zip(position, self._noise, strict=True))  # type: ignore[assignment]
        battery = v.battery
        return telemetry_snapshot(  # Telemetry(...), made faster (every engine period)
            self._now, position, v.velocity, yaw, battery.percent, battery.voltage, v.armed, v.landed_state,
            v.mode, True, self.world.home,
            v.wind if self._windy else None,
            self.link_ok(self._now) if self.config.link_loss is not None else None)

    @_locked
    def setpoint(self) -> Vector | None:
        """The position (ENU, from home) the vehicle's flight controller steers to; None when it flies on
        velocities, rests on the ground or falls."""
        return self._vehicle.setpoint

    @property
    def crashed(self) -> str | None:
        """Why the drone crashed, or None while it is fine."""
        return self._vehicle.crashed

    @_locked
    def observations(self) -> list[Observation]:
        """What the front and bottom cameras see from the drone's true pose now, nearest first."""
        if self._observations is None:
            v = self._vehicle
            self._observations = merge_observations(
                self.camera.observe(self.world, v.position, v.yaw, self._now),
                self.bottom_camera.observe(self.world, v.position, v.yaw, self._now),
                self._traffic(v.position, v.yaw))
            chance = self.config.detection_probability
            if chance < 1.0:  # a detector that misses: each object in view reported with this chance
                self._observations = [o for o in self._observations if self._weather.random() < chance]
        return list(self._observations)

    def _traffic(self, position: Vector, yaw: float) -> list[Observation]:
        """The other drones of the airspace that a camera sees (moving objects of shape ``drone``)."""
        if self.airspace is None:
            return []
        seen = []
        for name, where in self.airspace.others(self.call_sign):
            if any(camera.visible(self.world, position, yaw, where) for camera in (self.camera, self.bottom_camera)):
                seen.append(Observation("object", name, where, shape="drone", distance=math.dist(position, where)))
        return seen

    def events(self) -> list[DroneEvent]:
        if not self._vehicle.events:  # nothing happened (the usual answer, lock-free)
            return []
        with self._lock:
            out, self._vehicle.events = self._vehicle.events, []
            return out

    # --- commands ------------------------------------------------------------------------------------
    def _refuse(self, command: str, why: str, failure: Failure = Failure.DENIED) -> CommandHandle:
        logger.info("simulated drone: %s denied: %s", command, why)
        return CommandHandle.failed(command, failure, f"{command} denied: {why}")

    def _unflyable(self, command: str) -> CommandHandle | None:
        """A refusal when the drone cannot take flight commands (crashed, or landing on low battery)."""
        v = self._vehicle
        if v.crashed:
            return self._refuse(command, f"the drone has crashed ({v.crashed})")
        if v.failsafe and v.airborne:
            return self._refuse(command, f"low-battery failsafe: landing (battery {v.battery.percent:.1f}%)")
        return None

    def _outside(self, command: str, point: Vector) -> CommandHandle | None:
        if len(point) != 3 or not all(math.isfinite(p) for p in point):
            return self._refuse(command, f"the point {point} is not three finite numbers")
        if not self.world.inside(point):
            return self._refuse(command, f"{_fmt(point)} is outside the world's bounds (geofence)")
        return None

    @_command
    def arm(self) -> CommandHandle:
        v = self._vehicle
        if v.crashed:
            return self._refuse("arm", f"the drone has crashed ({v.crashed})")
        if v.armed:
            if v.airborne:
                return self._refuse("arm", "the drone is already flying")
            return CommandHandle.succeeded("arm")
        threshold = self.config.failsafe_battery_percent
        if v.battery.percent <= threshold:
            return self._refuse("arm", f"battery {v.battery.percent:.1f}% is at or below the {threshold:g}% minimum")
        v.arm()
        return CommandHandle.succeeded("arm")

    @_command
    def disarm(self) -> CommandHandle:
        v = self._vehicle
        if v.airborne and not v.crashed:
            return self._refuse("disarm", "the drone is flying (land first)")
        if v.armed:
            v.disarm("by command")
        return CommandHandle.succeeded("disarm")

    @_command
    def takeoff(self, altitude: float) -> CommandHandle:
        v = self._vehicle
        refusal = self._unflyable("takeoff")
        if refusal is not None:
            return refusal
        if not math.isfinite(altitude) or altitude <= 0.0:
            return self._refuse("takeoff", f"altitude {altitude} m is not above the ground")
        x, y, _ = v.position
        refusal = self._outside("takeoff", (x, y, altitude))
        if refusal is not None:
            return refusal
        if not v.armed:
            armed = self.arm()
            if not armed.ok:
                return CommandHandle.failed("takeoff", Failure.DENIED, f"takeoff denied: {armed.reason}")
        v.take_off(altitude)
        return CommandHandle.succeeded("takeoff")

    @_command
    def land(self) -> CommandHandle:
        v = self._vehicle
        if v.crashed:
            return self._refuse("land", f"the drone has crashed ({v.crashed})")
        if not v.airborne:
            if v.armed and v.phase == TAKEOFF:  # still on the ground: cancel the take-off
                v.fly_to(v.position, mode="LAND", phase=IDLE)
                return CommandHandle.succeeded("land")
            return self._refuse("land", "the drone is already on the ground")
        v.land()
        return CommandHandle.succeeded("land")

    @_command
    def goto(self, position: Vector, yaw: float | None = None, speed: float | None = None) -> CommandHandle:
        v = self._vehicle
        refusal = self._unflyable("goto") or self._outside("goto", tuple(position))
        if refusal is not None:
            return refusal
        if not v.armed or not (v.airborne or v.phase == TAKEOFF):
            return self._refuse("goto", "the drone is on the ground (take off first)")
        if speed is not None and not (math.isfinite(speed) and speed > 0.0):
            return self._refuse("goto", f"speed {speed} m/s is not a positive number")
        if yaw is not None and not math.isfinite(yaw):
            return self._refuse("goto", f"yaw {yaw} is not a number")
        speed = min(speed if speed is not None else self.config.cruise_speed, self.config.max_speed)
        v.fly_to(tuple(float(p) for p in position), mode="HOLD", speed=speed, yaw=yaw,  # type: ignore[arg-type]
                 face_travel=yaw is None, arrival_event=True)
        return CommandHandle.succeeded("goto")

    @_command
    def set_velocity(self, velocity: Vector, yaw_rate: float = 0.0) -> CommandHandle:
        v = self._vehicle
        refusal = self._unflyable("set_velocity")
        if refusal is not None:
            return refusal
        if len(velocity) != 3 or not all(math.isfinite(c) for c in velocity) or not math.isfinite(yaw_rate):
            return self._refuse("set_velocity", f"the velocity {velocity} / yaw rate {yaw_rate} is not finite numbers")
        if not v.armed:
            return self._refuse("set_velocity", "the drone is not armed")
        v.fly_velocity(tuple(float(c) for c in velocity), float(yaw_rate))  # type: ignore[arg-type]
        return CommandHandle.succeeded("set_velocity")

    @_command
    def offboard_position(self, position: Vector, yaw: float | None = None) -> CommandHandle:
        """Fly to an ENU setpoint in OFFBOARD mode (as PX4 does with streamed position setpoints)."""
        v = self._vehicle
        refusal = self._unflyable("offboard") or self._outside("offboard", tuple(position))
        if refusal is not None:
            return refusal
        if not v.armed:
            return self._refuse("offboard", "the drone is not armed")
        v.fly_to(tuple(float(p) for p in position), mode="OFFBOARD",  # type: ignore[arg-type]
                 yaw=yaw if yaw is not None and math.isfinite(yaw) else None)
        return CommandHandle.succeeded("offboard")

    @_command
    def hold(self) -> CommandHandle:
        refusal = self._unflyable("hold")
        if refusal is not None:
            return refusal
        self._vehicle.hold_here("HOLD")
        return CommandHandle.succeeded("hold")

    @_command
    def return_to_launch(self) -> CommandHandle:
        v = self._vehicle
        refusal = self._unflyable("return_to_launch")
        if refusal is not None:
            return refusal
        if not v.airborne:
            return self._refuse("return_to_launch", "the drone is on the ground")
        v.return_home()
        return CommandHandle.succeeded("return_to_launch")

    @_command
    def set_mode(self, name: str) -> CommandHandle:
        """Switch flight mode: HOLD, TAKEOFF (to the default altitude), LAND, RETURN or OFFBOARD."""
        mode = str(name).upper()
        if mode == "HOLD":
            return self.hold()
        if mode == "TAKEOFF":
            return self.takeoff(self.config.default_takeoff_altitude)
        if mode == "LAND":
            return self.land()
        if mode == "RETURN":
            return self.return_to_launch()
        if mode == "OFFBOARD":
            refusal = self._unflyable("offboard")
            if refusal is not None:
                return refusal
            self._vehicle.hold_here("OFFBOARD")
            return CommandHandle.succeeded("set_mode")
        return self._refuse("set_mode", f"mode {name!r} is not available in the simulation "
                            f"(one of {', '.join(MODES)})", Failure.UNSUPPORTED)

    # --- camera image and payload ---------------------------------------------------------------------
    def photo_source(self) -> str:
        """Its images (the engine saves them as photos), or none for a vehicle without a camera (``camera:
        false`` in its profile)."""
        return CAMERA_IMAGES if self.config.camera else CAMERA_NONE

    @_locked
    def capture_image(self, width: int = 640, height: int = 480) -> bytes | None:
        """A PNG of what the front camera sees now: the world rendered from the drone's true pose."""
        from aeroexec.drones.sim.render import SceneRenderer, to_png  # numpy and Pillow load on the first image

        if self._renderer is None or self._renderer.world is not self.world:
            self._renderer = SceneRenderer(self.world)
        v = self._vehicle
        return to_png(self._renderer.render(v.position, v.yaw, self.camera, self._now, width, height))

    def payload(self) -> list[str]:
        """The items the drone carries, in the order they are released (a copy made at once, without the lock: the
        telemetry beliefs ask it every update)."""
        return list(self._payload.carried)

    @_command
    def release_payload(self) -> CommandHandle:
        """Drop the first item carried: it falls and lands as an object of the world (see :mod:`.payload`)."""
        v = self._vehicle
        if v.crashed:
            return self._refuse("release_payload", f"the drone has crashed ({v.crashed})")
        item = self._payload.release(self.world, v.position, v.velocity, self._now, self.config.gravity)
        if item is None:
            return self._refuse("release_payload", "the drone carries nothing")
        v.events.append(DroneEvent(self._now, "payload_released", f"{item.name} released above "
                                   f"{_fmt(item.landing)}", {"item": item.name}))
        self._settle_payload()
        return CommandHandle.succeeded("release_payload")

    def _settle_payload(self) -> None:
        """Falling items that have landed become objects of the world."""
        if self._payload.falling:
            self.world, landed = self._payload.settle(self.world, self._now)
            for obj in landed:
                self._vehicle.events.append(DroneEvent(self._now, "payload_landed", f"{obj.name} landed at "
                                                       f"{_fmt(obj.position)}", {"item": obj.name}))
            if landed:
                self._observations = None

    def close(self) -> None:
        """Nothing to release: the simulation has no threads."""

    def __repr__(self) -> str:
        v = self._vehicle
        state = "crashed" if v.crashed else ("armed" if v.armed else "disarmed")
        return f"<SimulatedDrone {self.world.name!r} t={self._now:.2f} {_fmt(v.position)} {v.mode} {state}>"


__all__ = ["MODES", "SimulatedDrone"]
