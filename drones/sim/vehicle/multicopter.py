"""The simulated multicopter's physical state and flight phases, advanced one fixed substep at a time.

It does not check commands (``SimulatedDrone`` does): it flies the phase it is given, detects touch-down,
collisions, geofence breaches and low battery, and records what happened as :class:`DroneEvent`s.
"""

from __future__ import annotations

import logging
import math

from aeroexec.drones.interface import DroneEvent, LandedState
from aeroexec.drones.sim.config import SimConfig
from aeroexec.drones.sim.shapes import ObstacleIndex
from aeroexec.drones.sim.vehicle.battery import Battery
from aeroexec.drones.sim.vehicle.contact import Contacts
from aeroexec.drones.sim.vehicle.motion import (
    Limits,
    accelerate,
    clamp_velocity,
    desired_velocity,
    heading_to,
    stopping_point,
    turn_yaw,
    wrap180,
)
from aeroexec.drones.sim.world import World

logger = logging.getLogger(__name__)

Vector = tuple[float, float, float]

_GROUND_CONTACT = 0.02  # m: at or below this height, descending, the drone is on the ground
_ALTITUDE_REACHED = 0.1  # m: take-off and return climbs are done within it
_FACE_TRAVEL_MIN = 1.0  # m: farther than this from a target, the drone turns to face it

# Flight phases (what the drone is doing); the flight mode is what the autopilot reports.
IDLE, TAKEOFF, POSITION, VELOCITY, LAND, RETURN_CLIMB, RETURN_TRAVEL, RETURN_LAND, FALL = (
    "idle", "takeoff", "position", "velocity", "land", "return_climb", "return_travel", "return_land", "fall")
_TO_TARGET = frozenset((TAKEOFF, POSITION, RETURN_CLIMB, RETURN_TRAVEL))  # phases flying to a target point
_AT_REST: Vector = (0.0, 0.0, 0.0)


class Multicopter:
    """Position, velocity, yaw, motors, battery and the current flight phase of one simulated vehicle."""

    def __init__(self, world: World, config: SimConfig, start_time: float) -> None:
        self.world = world
        self.config = config
        self._obstacles = ObstacleIndex(world.obstacles, reach=config.drone_radius)  # collision broad phase
        self._limits: dict[tuple[float | None, float | None], Limits] = {}  # by (speed, climb): they are few
        self.time = start_time
        self.home: Vector = (float(config.start[0]), float(config.start[1]), 0.0)
        self.position: Vector = self.home
        self.velocity: Vector = (0.0, 0.0, 0.0)
        self.yaw = 0.0
        self.yaw_rate = 0.0  # deg/s over the last substep
        self.armed = False
        self.airborne = False
        self.mode = "MANUAL"
        self.phase = IDLE
        self.crashed: str | None = None  # why, once crashed
        self.failsafe = False  # latched by low battery
        self.battery = Battery(config)
        self.wind: tuple[float, float] = (0.0, 0.0)  # m/s east, north, now (the drone sets the gusts)
        self.events: list[DroneEvent] = []
        self._target: Vector = self.position
        self._speed = config.cruise_speed
        self._target_yaw: float | None = None
        self._face_travel = False
        self._arrival_pending = False
        self._velocity_cmd: Vector = (0.0, 0.0, 0.0)
        self._yaw_rate_cmd = 0.0
        self._ground_since = start_time
        self._flew_since_armed = False
        self._outside = False
        self.contacts = Contacts(world, config.touch_distance)  # the platform's deck, touched objects
        self._bounds = (world.bounds.lower, world.bounds.upper)
        self._fences = bool(getattr(world, "fences", ()))
        self._battery_watch = max(config.failsafe_battery_percent, 0.0)  # at or below it, the battery is checked
        # above this height, a substep can reach neither the ground nor the platform's deck (at its highest)
        self._contact_height = max(self.contacts.deck_top() or 0.0, 0.0) + _GROUND_CONTACT + 1e-6
        # what a substep need not look at in a world without it (the answer is known: no collision, no touch)
        self._solids = bool(self._obstacles.obstacles)
        self._touchables = self.contacts.touchables

    # --- reported state -----------------------------------------------------------------------------
    @property
    def setpoint(self) -> Vector | None:
        """The position the flight controller steers to now; None when it flies on velocities or rests."""
        return None if self.phase in (IDLE, VELOCITY, FALL) else self._target

    @property
    def landed_state(self) -> LandedState:
        if not self.airborne:
            return LandedState.TAKING_OFF if self.phase == TAKEOFF else LandedState.ON_GROUND
        if self.phase == TAKEOFF and not self._flew_since_armed:
            return LandedState.TAKING_OFF
        if self.phase in (LAND, RETURN_LAND):
            return LandedState.LANDING
        return LandedState.IN_AIR

    def emit(self, kind: str, detail: str = "", **data: object) -> None:
        logger.info("simulated drone at t=%.2f: %s%s", self.time, kind, f" ({detail})" if detail else "")
        self.events.append(DroneEvent(self.time, kind, detail, dict(data)))

    def limits(self, speed: float | None = None, climb: float | None = None) -> Limits:
        found = self._limits.get((speed, climb))
        if found is None:
            found = self._limits[(speed, climb)] = self._new_limits(speed, climb)
        return found

    def _new_limits(self, speed: float | None, climb: float | None) -> Limits:
        c = self.config
        return Limits(
            horizontal_speed=min(speed if speed is not None else c.cruise_speed, c.max_speed),
            climb_rate=climb if climb is not None else c.max_climb_rate,
            descent_rate=c.descent_rate,
            horizontal_acceleration=c.max_acceleration,
            vertical_acceleration=c.vertical_acceleration,
            position_gain=c.position_gain,
        )

    # --- phases (set by the drone's commands) ---------------------------------------------------------
    def arm(self) -> None:
        self.armed = True
        self._ground_since = self.time
        self._flew_since_armed = False
        if self.mode == "MANUAL":
            self.mode = "HOLD"
        self.phase = IDLE
        self.emit("armed")

    def disarm(self, why: str = "") -> None:
        self.armed = False
        self.mode = "MANUAL"
        self.phase = IDLE
        self.velocity = (0.0, 0.0, 0.0)
        self.emit("disarmed", why)

    def fly_to(self, target: Vector, *, mode: str, speed: float | None = None, yaw: float | None = None,
               face_travel: bool = False, arrival_event: bool = False, phase: str = POSITION) -> None:
        self.phase = phase
        self.mode = mode
        self._target = target
        self._speed = speed if speed is not None else self.config.cruise_speed
        self._target_yaw = yaw
        self._face_travel = face_travel
        self._arrival_pending = arrival_event

    def hold_here(self, mode: str = "HOLD") -> None:
        if self.airborne:
            stop = stopping_point(self.position, self.velocity, self.limits())
            self.fly_to(stop, mode=mode)
        else:
            self.mode = mode
            self.phase = IDLE

    def fly_velocity(self, velocity: Vector, yaw_rate: float) -> None:
        self.phase = VELOCITY
        self.mode = "OFFBOARD"
        self._velocity_cmd = clamp_velocity(velocity, self.limits(self.config.max_speed))
        self._yaw_rate_cmd = max(-self.config.yaw_rate, min(self.config.yaw_rate, yaw_rate))

    def take_off(self, altitude: float) -> None:
        x, y, _ = self.position
        self.fly_to((x, y, altitude), mode="TAKEOFF", phase=TAKEOFF)

    def land(self, mode: str = "LAND") -> None:
        stop = stopping_point(self.position, self.velocity, self.limits())
        self.fly_to((stop[0], stop[1], 0.0), mode=mode, phase=LAND if mode == "LAND" else RETURN_LAND)

    def return_home(self) -> None:
        ceiling = self.world.bounds.upper[2] - 1.0
        altitude = max(self.position[2], min(self.config.return_altitude, ceiling))
        if self._from_home() <= self.config.acceptance_radius:
            self.fly_to(self.home, mode="RETURN", phase=RETURN_LAND)
        else:
            self.fly_to((self.position[0], self.position[1], altitude), mode="RETURN", phase=RETURN_CLIMB)

    def _from_home(self) -> float:
        """Horizontal distance (m) to where the drone started."""
        return math.hypot(self.position[0] - self.home[0], self.position[1] - self.home[1])

    # --- substeps -------------------------------------------------------------------------------------
    def advance(self, start: float, done: int, target: int, dt: float) -> int:
        """Substeps ``done + 1`` to ``target`` (at ``start + k * dt``): :meth:`hold_still` while the vehicle
        :meth:`holds_still`, else one :meth:`step` at a time; disarmed (and not falling), nothing moves: its clock
        skips to the last substep. The number of the last substep made (``target``, or ``done`` when later)."""
        if not self.armed and self.phase != FALL:
            done = max(done, target)  # nothing moves: skip ahead
            self.time = start + done * dt
        while done < target:
            if self.holds_still():  # only the clock and the battery move: the substeps without the rest
                done = self.hold_still(start, done, target, dt)
                continue
            done += 1
            self.step(start + done * dt, dt)
            if not self.armed and self.phase != FALL:
                done = target
                self.time = start + target * dt
        return done

    def carried(self, now: float) -> tuple[Vector, float]:
        """Position and yaw at ``now``: the state of the last whole substep carried over the remainder (less than a
        substep; none when ``now`` is earlier), never below the ground."""
        ahead = now - self.time
        if ahead < 0.0:
            ahead = 0.0
        (px, py, pz), (ux, uy, uz) = self.position, self.velocity
        z = pz + uz * ahead
        return (px + ux * ahead, py + uy * ahead, 0.0 if z < 0.0 else z), wrap180(self.yaw + self.yaw_rate * ahead)

    def step(self, t: float, dt: float) -> None:
        """Advance the vehicle from ``self.time`` to ``t`` (``dt`` seconds later)."""
        self.time = round(t, 9)
        if self.phase == FALL:
            self._fall(dt)
            return
        if not self.armed:
            self.yaw_rate = 0.0
            return
        x, y, previous_z = self.position
        velocity = self.velocity
        if velocity == _AT_REST and self.phase in _TO_TARGET and self._on_target():
            # the controller's fixed point (hovering on its target): _desired would neither turn the yaw nor ask for
            # a velocity, and accelerate from rest toward rest gives rest, (0.0, 0.0, 0.0): the same, without them
            self.yaw_rate = 0.0
            velocity = _AT_REST
        else:
            yaw_before = self.yaw
            desired, limits = self._desired(dt)
            yaw = self.yaw
            # a yaw that did not turn: wrap180(0.0) / dt, without the call
            self.yaw_rate = 0.0 if yaw == yaw_before else wrap180(yaw - yaw_before) / dt
            velocity = accelerate(velocity, desired, limits, dt)
        vx, vy, vz = velocity
        airspeed = None
        wx, wy = self.wind
        if (wx != 0.0 or wy != 0.0) and self.airborne:  # the air moves: the motors fly the airspeed
            velocity, airspeed = self._in_wind(velocity)
            vx, vy, vz = velocity
        if not self.airborne and vz <= 0.0:
            self.velocity = (0.0, 0.0, 0.0)
            self.ride_deck()
            self._ground_idle()
            self.battery.drain(dt, True, False, 0.0, 0.0)
            return
        self.velocity = velocity
        position = self.position = (x + vx * dt, y + vy * dt, previous_z + vz * dt)
        z = position[2]
        if not self.airborne and z > 0.0:
            self.airborne = True
            self.contacts.leave()
        self.battery.drain_flying(dt, math.hypot(vx, vy) if airspeed is None else airspeed, vz)
        if vz <= 0.0 and z <= self._contact_height:  # higher, neither the ground nor the deck is reached
            deck = self.contacts.deck_below(position, self.time, previous_z)
            if z <= (deck or 0.0) + _GROUND_CONTACT:
                self._touch_down(deck)
                return
        if (self._solids and self._check_collision()) or (self.battery.percent <= self._battery_watch
                                                           and self._check_battery()):
            return
        if self._touchables:
            for name, where in self.contacts.touches(position, self.time):
                self.emit("touched", f"{name} at ({where[0]:.1f}, {where[1]:.1f}, {where[2]:.1f})", object=name,
                          position=where)
        low, high = self._bounds
        if (low[0] <= position[0] <= high[0] and low[1] <= position[1] <= high[1]
                and low[2] <= z <= high[2]) and not (self._fences and not self.world.inside(position)):
            self._outside = False  # inside the geofence (``World.inside``)
        else:
            self._check_bounds()
        self._progress()

    def holds_still(self) -> bool:
        """Hovering on its position target in calm air, with nothing a substep would find: inside the geofence, off
        every solid, touching nothing, high above the ground and the deck, no arrival to report. Then a substep
        moves only the clock and the battery (:meth:`hold_still`), until the battery's watch changes the phase."""
        wx, wy = self.wind
        position = self.position
        if not (self.phase == POSITION and self.armed and self.airborne and not self._arrival_pending
                and wx == 0.0 and wy == 0.0 and not self._touchables and self.velocity == _AT_REST
                and position[2] > self._contact_height and self._on_target()):
            return False
        low, high = self._bounds
        inside = (low[0] <= position[0] <= high[0] and low[1] <= position[1] <= high[1]
                  and low[2] <= position[2] <= high[2]) and not (self._fences and not self.world.inside(position))
        return inside and not (self._solids and self._obstacles.collides(position, self.config.drone_radius))

    def hold_still(self, start: float, done: int, last: int, dt: float) -> int:
        """Substeps ``done + 1`` to ``last`` (at ``start + k * dt``) of a vehicle that :meth:`holds_still`: what
        :meth:`step` would do, bit for bit, at the control laws' fixed point where every check finds what it found
        the substep before (the same position; nothing that moves to touch); the number of the last substep made
        (earlier than ``last`` once the battery's watch crashed the vehicle or made it land)."""
        x, y, z = self.position
        battery, watch = self.battery, self._battery_watch
        while done < last:
            done += 1
            self.time = round(start + done * dt, 9)
            self.yaw_rate = 0.0
            self.velocity = _AT_REST
            self.position = (x + 0.0, y + 0.0, z + 0.0)  # x + vx * dt, with vx 0.0
            battery.drain_flying(dt, 0.0, 0.0)
            if battery.percent <= watch:
                if self._check_battery():
                    return done  # crashed: the rest of the substep is not made
                if self.phase != POSITION:  # the failsafe lands: the rest of the substep, then step again
                    self._outside = False
                    self._flew_since_armed = True
                    return done
            self._outside = False
            self._flew_since_armed = True
        return done

    def _on_target(self) -> bool:
        """On the target point and facing the yaw asked, as the control laws see it: ``desired_velocity`` asks for
        none (the same distance, under its 1e-9 m) and ``turn_yaw`` leaves the yaw where it is."""
        target_yaw = self._target_yaw
        if target_yaw is not None and self.yaw != wrap180(target_yaw):
            return False
        (px, py, pz), (tx, ty, tz) = self.position, self._target
        dx, dy, dz = tx - px, ty - py, tz - pz
        return math.sqrt(dx * dx + dy * dy + dz * dz) < 1e-9

    def _in_wind(self, velocity: Vector) -> tuple[Vector, float]:
        """The ground velocity the controller gets in the wind (its airspeed at most ``max_speed``: upwind it is
        slowed, in a wind stronger than that it drifts), and the horizontal airspeed it flies."""
        vx, vy, vz = velocity
        wx, wy = self.wind
        ax, ay = vx - wx, vy - wy
        air = math.hypot(ax, ay)
        top = self.config.max_speed
        if air > top:
            k = top / air
            return (wx + ax * k, wy + ay * k, vz), top
        return velocity, air

    def _desired(self, dt: float) -> tuple[Vector, Limits]:
        c = self.config
        if self.phase == VELOCITY:
            self.yaw = wrap180(self.yaw + self._yaw_rate_cmd * dt)
            return self._velocity_cmd, self.limits(c.max_speed)
        if self.phase in _TO_TARGET:
            limits = self.limits(self._speed, c.climb_rate if self.phase == TAKEOFF else None)
            position, target, target_yaw = self.position, self._target, self._target_yaw
            if (target_yaw is None and self._face_travel
                    and math.hypot(position[0] - target[0], position[1] - target[1]) > _FACE_TRAVEL_MIN):
                target_yaw = heading_to(position, target)
            if target_yaw is not None:
                self.yaw = turn_yaw(self.yaw, target_yaw, c.yaw_rate, dt)
            return desired_velocity(position, self.velocity, target, limits, dt), limits
        if self.phase in (LAND, RETURN_LAND):
            limits = self.limits()
            x, y, z = self.position
            above_target = (self._target[0], self._target[1], z)
            vx, vy, _ = desired_velocity(self.position, self.velocity, above_target, limits, dt)
            return (vx, vy, -self._landing_speed(z)), limits
        return (0.0, 0.0, 0.0), self.limits()

    def _landing_speed(self, z: float) -> float:
        c = self.config
        if z >= c.land_fast_altitude:
            return c.descent_rate
        if z <= c.land_slow_altitude:
            return c.land_speed
        f = (z - c.land_slow_altitude) / (c.land_fast_altitude - c.land_slow_altitude)
        return c.land_speed + f * (c.descent_rate - c.land_speed)

    def _ground_idle(self) -> None:
        """On the ground with motors armed: auto-disarm after the landing or pre-flight delay."""
        c = self.config
        delay = c.disarm_delay if self._flew_since_armed else c.preflight_disarm_delay
        if self.phase == TAKEOFF:
            return
        if self.time - self._ground_since >= delay - 1e-9:
            why = "auto-disarmed after landing" if self._flew_since_armed else "auto-disarmed: armed without taking off"
            self.disarm(why)

    def ride_deck(self) -> None:
        """On the platform's deck: move with it (the drone stands where the deck carries it)."""
        riding = self.contacts.ride(self.time)
        if riding is not None and not self.airborne:
            self.position, self.velocity = riding

    def _touch_down(self, deck: float | None = None) -> None:
        """Touch the ground, or the platform's deck at height ``deck``."""
        speed = -self.velocity[2]
        x, y, _ = self.position
        self.position = (x, y, 0.0 if deck is None else deck)
        self.velocity = (0.0, 0.0, 0.0)
        self.airborne = False
        platform = self.world.platform.name if deck is not None and self.world.platform else ""
        surface = "the ground" if deck is None else f"the deck of '{platform}'"
        if speed > self.config.crash_speed:
            if deck is not None:  # the wreck lies on the deck and rides along
                self.position = self.contacts.board(self.position, self.time)[0]
            self._crash(f"hit {surface} at {speed:.1f} m/s", kind="collision", obstacle=platform or "ground")
            return
        self._flew_since_armed = True
        self._ground_since = self.time
        self.phase = IDLE
        if deck is None:
            self.emit("landed", f"at ({x:.1f}, {y:.1f})", position=(x, y, 0.0))
            return
        self.position, self.velocity = self.contacts.board(self.position, self.time)
        self.emit("landed", f"on {surface} at ({x:.1f}, {y:.1f}, {deck:.1f})", position=self.position,
                  platform=platform)

    def _crash(self, why: str, kind: str, **data: object) -> None:
        self.crashed = why
        self.armed = False
        self.mode = "MANUAL"
        self.phase = FALL if self.airborne else IDLE
        self.velocity = (0.0, 0.0, min(self.velocity[2], 0.0))
        self.emit(kind, why, position=self.position, **data)

    def _fall(self, dt: float) -> None:
        vz = self.velocity[2] - self.config.gravity * dt
        x, y, z = self.position
        z += vz * dt
        if z <= 0.0:
            self.position, self.velocity, self.airborne, self.phase = (x, y, 0.0), (0.0, 0.0, 0.0), False, IDLE
        else:
            self.position, self.velocity = (x, y, z), (0.0, 0.0, vz)

    def _check_collision(self) -> bool:
        obstacle = self._obstacles.collides(self.position, self.config.drone_radius)
        if obstacle is None:
            return False
        x, y, z = self.position
        self._crash(f"collided with '{obstacle.name}' at ({x:.1f}, {y:.1f}, {z:.1f})", kind="collision",
                    obstacle=obstacle.name)
        return True

    def _check_battery(self) -> bool:
        percent = self.battery.percent
        if percent <= 0.0:
            self._crash("the battery is empty: the motors stopped", kind="battery_empty")
            return True
        if not self.failsafe and percent <= self.config.failsafe_battery_percent:
            self.failsafe = True
            threshold = self.config.failsafe_battery_percent
            self.emit("failsafe", f"battery {percent:.1f}% at or below {threshold:g}%: landing",
                      battery_percent=percent)
            self.land()
        return False

    def _check_bounds(self) -> None:
        if self.world.inside(self.position):
            self._outside = False
            return
        if self._outside:
            return
        self._outside = True
        x, y, z = self.position
        self.emit("out_of_bounds", f"left the geofence at ({x:.1f}, {y:.1f}, {z:.1f}): holding inside",
                  position=self.position)
        if self.phase in (POSITION, VELOCITY, TAKEOFF):
            self.fly_to(self.world.bounds.clamp(self.position, margin=0.5), mode="HOLD")

    def _progress(self) -> None:
        """Finish phases whose goal is reached."""
        c = self.config
        if self.phase in (TAKEOFF, RETURN_CLIMB) and abs(self.position[2] - self._target[2]) <= _ALTITUDE_REACHED:
            if self.phase == TAKEOFF:
                self._flew_since_armed = True
                self.fly_to(self._target, mode="HOLD")
                self.emit("takeoff_complete", f"at {self.position[2]:.1f} m")
            else:
                self.fly_to((self.home[0], self.home[1], self._target[2]), mode="RETURN", face_travel=True,
                            phase=RETURN_TRAVEL)
        elif self.phase == RETURN_TRAVEL and self._from_home() <= c.acceptance_radius:
            self.fly_to(self.home, mode="RETURN", phase=RETURN_LAND)
        elif (self.phase == POSITION and self._arrival_pending
              and math.dist(self.position, self._target) <= c.acceptance_radius):
            self._arrival_pending = False
            x, y, z = self._target
            self.emit("arrived", f"at ({x:.1f}, {y:.1f}, {z:.1f})", position=self._target)
        if self.airborne and self.phase not in (TAKEOFF,):
            self._flew_since_armed = True
