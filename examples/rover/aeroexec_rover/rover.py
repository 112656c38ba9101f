"""A simulated differential-drive rover: unicycle kinematics in an aeroexec world file, on the engine's clock.

Obstacles are walls: the rover stops against them and its bumper is pressed. A world object named ``dock`` is
its charging dock: docked, the battery charges. Commands are accepted at once and followed on each ``update``;
the behaviors watch the telemetry to know when a goal is reached, as they do with a drone.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

from aeroexec.drones import CommandHandle, DroneEvent, Failure, LandedState, Observation, Robot, Telemetry
from aeroexec.drones.sim import Camera, World

BODY_RADIUS = 0.35  # m: the bumper touches an obstacle closer than this to the rover's center
SENSOR_HEIGHT = 0.3  # m: the camera and the bumper above the ground
STEP = 0.05  # s: integration substep
DOCK_RADIUS = 0.4  # m: docked within this distance of the dock, when still


@dataclass
class RoverConfig:
    """The rover's limits and its battery."""

    max_speed: float = 1.0  # m/s
    max_turn_rate: float = 90.0  # deg/s
    acceleration: float = 1.0  # m/s²
    battery: float = 100.0  # percent at the start
    drain_still: float = 0.02  # percent per second
    drain_driving: float = 0.25  # percent per second at full speed
    charge_rate: float = 2.0  # percent per second on the dock


def wrap180(angle: float) -> float:
    return (angle + 180.0) % 360.0 - 180.0


class SimulatedRover(Robot):
    """A rover at ``start`` (x, y) facing ``heading`` degrees (0 east, counterclockwise); thread-safe."""

    def __init__(self, world: World, *, config: RoverConfig | None = None, start: tuple[float, float] = (0.0, 0.0),
                 heading: float = 0.0, start_time: float = 0.0) -> None:
        self.world, self.config = world, config or RoverConfig()
        self.camera = Camera.from_settings(world.camera)
        self.x, self.y, self.heading = float(start[0]), float(start[1]), float(heading)
        self.speed = 0.0  # m/s along the heading
        self.turn_rate = 0.0  # deg/s
        self.battery = self.config.battery
        self.bumper = False
        self._now = start_time
        self._lock = threading.RLock()
        self._goal: tuple[float, float] | None = None  # drive_to target
        self._goal_speed = self.config.max_speed
        self._turn_goal: float | None = None
        self._command = (0.0, 0.0)  # set_motion (speed, turn rate)
        self._mode = "STILL"
        self._events: list[DroneEvent] = []
        dock = next((o for o in world.objects if o.name == "dock"), None)
        self.dock_position = (dock.position[0], dock.position[1]) if dock is not None else None

    # -- the Robot interface -------------------------------------------------------------------------
    def update(self, now: float) -> None:
        with self._lock:
            while self._now + STEP <= now + 1e-9:
                self._step(STEP)
                self._now += STEP

    def telemetry(self) -> Telemetry:
        with self._lock:
            rad = math.radians(self.heading)
            return Telemetry(time=self._now, position=(self.x, self.y, 0.0),
                             velocity=(self.speed * math.cos(rad), self.speed * math.sin(rad), 0.0),
                             yaw=wrap180(self.heading), battery_percent=self.battery, armed=True,
                             landed_state=LandedState.ON_GROUND, flight_mode=self.mode)

    def hold(self) -> CommandHandle:
        return self.stop()

    def observations(self) -> list[Observation]:
        with self._lock:
            return self.camera.observe(self.world, (self.x, self.y, SENSOR_HEIGHT), self.heading, self._now)

    def events(self) -> list[DroneEvent]:
        with self._lock:
            out, self._events = self._events, []
            return out

    # -- the rover's commands -------------------------------------------------------------------------
    @property
    def mode(self) -> str:
        """DOCKED, STILL or DRIVING: the rover's motion state."""
        if self.docked:
            return "DOCKED"
        return "DRIVING" if abs(self.speed) > 0.02 or abs(self.turn_rate) > 1.0 else "STILL"

    @property
    def docked(self) -> bool:
        return (self.dock_position is not None and abs(self.speed) < 0.02
                and math.dist((self.x, self.y), self.dock_position) <= DOCK_RADIUS)

    def drive_to(self, point: tuple[float, float], speed: float | None = None) -> CommandHandle:
        """Turn toward ``point`` and drive there, then stop."""
        if not self.world.inside((point[0], point[1], SENSOR_HEIGHT)):
            return CommandHandle.failed("drive_to", Failure.DENIED, f"({point[0]:.1f}, {point[1]:.1f}) is outside "
                                                                     "the yard")
        with self._lock:
            self._goal, self._turn_goal, self._command = (float(point[0]), float(point[1])), None, (0.0, 0.0)
            self._goal_speed = min(speed or self.config.max_speed, self.config.max_speed)
        return CommandHandle.succeeded("drive_to")

    def turn_to(self, heading: float) -> CommandHandle:
        """Turn in place to ``heading`` degrees."""
        with self._lock:
            self._goal, self._turn_goal, self._command = None, float(heading), (0.0, 0.0)
        return CommandHandle.succeeded("turn_to")

    def set_motion(self, speed: float, turn_rate: float) -> CommandHandle:
        """Drive at ``speed`` m/s turning at ``turn_rate`` deg/s until told otherwise."""
        with self._lock:
            self._goal = self._turn_goal = None
            self._command = (max(-self.config.max_speed, min(self.config.max_speed, speed)),
                             max(-self.config.max_turn_rate, min(self.config.max_turn_rate, turn_rate)))
        return CommandHandle.succeeded("set_motion")

    def stop(self) -> CommandHandle:
        with self._lock:
            self._goal = self._turn_goal = None
            self._command = (0.0, 0.0)
        return CommandHandle.succeeded("stop")

    def distance_ahead(self, bearing: float = 0.0, reach: float = 5.0) -> float:
        """Meters to the nearest obstacle along a ray ``bearing`` degrees left of the heading (at most ``reach``)."""
        rad = math.radians(self.heading + bearing)
        travelled = 0.0
        while travelled < reach:
            point = (self.x + travelled * math.cos(rad), self.y + travelled * math.sin(rad), SENSOR_HEIGHT)
            gap = self.world.distance_to_obstacle(point)
            if gap < 0.02:
                return travelled
            travelled += max(gap, 0.02)
        return reach

    # -- the physics ------------------------------------------------------------------------------------
    def _wanted(self) -> tuple[float, float]:
        if self._goal is not None:
            dx, dy = self._goal[0] - self.x, self._goal[1] - self.y
            distance = math.hypot(dx, dy)
            if distance < 0.05:
                self._goal = None
                return 0.0, 0.0
            error = wrap180(math.degrees(math.atan2(dy, dx)) - self.heading)
            turn = max(-self.config.max_turn_rate, min(self.config.max_turn_rate, 3.0 * error))
            ahead = max(0.0, math.cos(math.radians(error))) if abs(error) < 60 else 0.0
            return min(self._goal_speed, math.sqrt(2 * self.config.acceleration * distance)) * ahead, turn
        if self._turn_goal is not None:
            error = wrap180(self._turn_goal - self.heading)
            if abs(error) < 0.5:
                self._turn_goal = None
                return 0.0, 0.0
            return 0.0, max(-self.config.max_turn_rate, min(self.config.max_turn_rate, 3.0 * error))
        return self._command

    def _step(self, dt: float) -> None:
        speed, turn = self._wanted()
        change = max(-self.config.acceleration * dt, min(self.config.acceleration * dt, speed - self.speed))
        self.speed += change
        self.turn_rate = turn
        self.heading = wrap180(self.heading + turn * dt)
        rad = math.radians(self.heading)
        nx, ny = self.x + self.speed * dt * math.cos(rad), self.y + self.speed * dt * math.sin(rad)
        blocked = self.world.distance_to_obstacle((nx, ny, SENSOR_HEIGHT)) < BODY_RADIUS \
            or not self.world.inside((nx, ny, SENSOR_HEIGHT))
        if blocked and abs(self.speed) > 0:
            if not self.bumper:
                self._events.append(DroneEvent(self._now, "collision", "the bumper is pressed"))
            self.bumper = True
            self.speed = 0.0
            self._goal = None
            self._command = (0.0, self._command[1])
        else:
            self.x, self.y = nx, ny
            if self.world.distance_to_obstacle((self.x, self.y, SENSOR_HEIGHT)) >= BODY_RADIUS + 0.05:
                self.bumper = False
        drain = self.config.drain_still + self.config.drain_driving * abs(self.speed) / self.config.max_speed
        if self.docked:
            self.battery = min(100.0, self.battery + self.config.charge_rate * dt)
        else:
            self.battery = max(0.0, self.battery - drain * dt)
