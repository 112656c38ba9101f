"""What a flight home costs, from a vehicle model (distance, climb, speed, wind), and the predicates safety rules
read that are computed from it: ``battery_to_home``, ``return_margin``, ``rally_distance``, ``mission_time``.

The model is the simulated drone's own (``drones/sim/battery.py``: minutes of hover, extra drain with airspeed and
climb) with its parameters when the robot is the simulator, the same defaults otherwise; a flight home climbs to
the return altitude, flies at cruise speed against the wind the vehicle reports, descends and lands.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from aeroexec.beliefs import BeliefMemory

Point = tuple[float, float, float]
SETTLE = 4.0  # s a return spends arriving and starting its landing, beyond the leg and the descent


@dataclass(frozen=True)
class VehicleModel:
    """The figures a return estimate needs (the simulated drone's :class:`SimConfig` has them all)."""

    cruise_speed: float = 5.0  # m/s
    max_speed: float = 12.0  # m/s: the most airspeed the vehicle flies
    max_climb_rate: float = 3.0  # m/s
    max_acceleration: float = 3.0  # m/s^2, horizontal
    descent_rate: float = 1.5  # m/s
    land_speed: float = 0.7  # m/s below land_slow_altitude
    land_slow_altitude: float = 5.0  # m
    land_fast_altitude: float = 10.0  # m: between the two, the descent slows from descent_rate to land_speed
    return_altitude: float = 10.0  # m: a return climbs to it first
    battery_hover_minutes: float = 20.0
    battery_speed_drain: float = 0.5
    battery_climb_drain: float = 0.5
    home: Point = (0.0, 0.0, 0.0)
    position_noise: float = 0.0  # m: the standard deviation of reported positions

    @classmethod
    def of(cls, robot: Any) -> VehicleModel:
        """The model of ``robot``: its simulator settings when it has them, the defaults otherwise."""
        config = getattr(robot, "config", None)
        if config is None:
            return cls()
        names = [f for f in cls.__dataclass_fields__ if f not in ("home", "position_noise") and hasattr(config, f)]
        start = getattr(config, "start", (0.0, 0.0))
        return cls(**{f: float(getattr(config, f)) for f in names}, home=(float(start[0]), float(start[1]), 0.0),
                   position_noise=float(getattr(config, "position_noise_std", 0.0)))

    @property
    def hover_rate(self) -> float:
        """Percent of charge per second hovering."""
        return 100.0 / (self.battery_hover_minutes * 60.0)

    @property
    def max_drain(self) -> float:
        """The most percent per second the battery can lose (full airspeed and climb)."""
        return self.hover_rate * (1.0 + self.battery_speed_drain + self.battery_climb_drain)

    def drain(self, airspeed: float, climb: float = 0.0) -> float:
        """Percent per second at ``airspeed`` (horizontal) and ``climb`` (m/s, up)."""
        return self.hover_rate * (1.0 + self.battery_speed_drain * (airspeed / self.max_speed) ** 2
                                  + self.battery_climb_drain * max(climb, 0.0) / self.max_climb_rate)

    def leg(self, start: Point, end: Point, wind: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float]:
        """Seconds and percent of charge to fly from ``start`` to ``end`` (a level leg at cruise speed against
        ``wind``, then the climb or descent)."""
        dx, dy = end[0] - start[0], end[1] - start[1]
        distance = math.hypot(dx, dy)
        seconds = percent = 0.0
        if distance > 1e-6:
            ux, uy = dx / distance, dy / distance
            ground = self.cruise_speed
            ax, ay = ux * ground - wind[0], uy * ground - wind[1]
            air = math.hypot(ax, ay)
            if air > self.max_speed:  # the wind slows it: the ground speed at full airspeed along the track
                along = wind[0] * ux + wind[1] * uy
                cross = -wind[0] * uy + wind[1] * ux
                ground = along + math.sqrt(max(self.max_speed ** 2 - cross ** 2, 0.0))
                air = self.max_speed
            if ground <= 0.1:
                return math.inf, math.inf
            seconds = distance / ground
            percent = seconds * self.drain(air)
        rise = end[2] - start[2]
        hover_air = math.hypot(*wind)
        if rise > 0:
            t = rise / self.max_climb_rate
            seconds, percent = seconds + t, percent + t * self.drain(hover_air, self.max_climb_rate)
        elif rise < 0:
            t = self.descent_seconds(start[2]) - self.descent_seconds(end[2])
            seconds, percent = seconds + t, percent + t * self.drain(hover_air)
        return seconds, percent

    def descent_seconds(self, height: float) -> float:
        """Seconds to descend from ``height`` to the ground as a landing does (slowing down between the fast and
        the slow altitudes, the simulator's and PX4's MPC_LAND_ALT1/2)."""
        low, high = self.land_slow_altitude, max(self.land_fast_altitude, self.land_slow_altitude)
        seconds = min(max(height, 0.0), low) / self.land_speed
        middle = min(max(height - low, 0.0), high - low)
        if middle > 0.0:
            v0, v1 = self.land_speed, self.descent_rate
            span = high - low
            if abs(v1 - v0) < 1e-9:
                seconds += middle / v0
            else:  # v(z) = v0 + (z - low) / span * (v1 - v0): the time is a logarithm
                seconds += span / (v1 - v0) * math.log((v0 + middle / span * (v1 - v0)) / v0)
        return seconds + max(height - high, 0.0) / self.descent_rate

    def to_home(self, position: Sequence[float], wind: tuple[float, float] = (0.0, 0.0),
                home: Point | None = None) -> float:
        """Percent of charge a flight from ``position`` to ``home`` (default: the model's) and a landing take."""
        home = home or self.home
        here = (float(position[0]), float(position[1]), float(position[2]))
        altitude = here[2]
        if math.hypot(here[0] - home[0], here[1] - home[1]) > 1.0:
            altitude = max(here[2], self.return_altitude)
        _, climb = self.leg(here, (here[0], here[1], altitude), wind)
        _, travel = self.leg((here[0], here[1], altitude), (home[0], home[1], altitude), wind)
        _, descend = self.leg((home[0], home[1], altitude), (home[0], home[1], 0.0), wind)
        settle = SETTLE * self.drain(math.hypot(*wind))  # braking at home and the landing's start
        return climb + travel + descend + settle

    def home_rate(self, horizontal: float, vertical: float) -> float:
        """A bound on how fast :meth:`to_home` changes (percent per second) while the vehicle moves at most
        ``horizontal`` and ``vertical`` m/s: the cost of a meter farther (at half the cruise speed, into wind)
        and of a meter higher (descending it at the landing speed)."""
        worst = self.drain(self.max_speed, self.max_climb_rate)
        return worst / (0.5 * self.cruise_speed) * horizontal + worst / self.land_speed * vertical


class SafetyPredicates:
    """Registers the computed predicates of safety rules on a belief memory, reading the drone's position, charge
    and wind from the memory (what the rules see); ``stopping_point`` also reads the velocity from ``velocity()``
    (the telemetry's)."""

    def __init__(self, memory: BeliefMemory, model: VehicleModel, now: Callable[[], float],
                 velocity: Callable[[], Sequence[float]] = lambda: (0.0, 0.0, 0.0)) -> None:
        self.memory, self.model, self.now, self.velocity = memory, model, now, velocity
        self.mission_started: float | None = None
        self.rally_points: list[Point] = []

    def register(self) -> None:
        memory = self.memory
        memory.register("battery_to_home", 2, self._battery_to_home)
        memory.register("return_margin", 2, self._return_margin)
        memory.register("rally_distance", 2, self._rally_distance)
        memory.register("mission_time", 1, self._mission_time)
        memory.register("stopping_point", 2, self._stopping_point)

    # -- what the rules read ---------------------------------------------------------------------------
    def wind(self) -> tuple[float, float]:
        found = self.memory.query("wind(self, ?w)")
        speed = float(found["?w"]) if found and isinstance(found["?w"], int | float) else 0.0
        return (speed, 0.0) if speed else (0.0, 0.0)  # against the drone, whatever its heading: the worst case

    def position(self, who: Any) -> Point | None:
        if who == "self":
            found = self.memory.query("position(self, ?p)")
            who = found["?p"] if found else None
        if isinstance(who, tuple) and len(who) == 3 and all(isinstance(v, int | float) for v in who):
            return (float(who[0]), float(who[1]), float(who[2]))
        return None

    def _battery_to_home(self, who: Any) -> float | None:
        point = self.position(who)
        if point is None:
            return None
        return round(self._worst_case(point), 1)

    def _worst_case(self, point: Point) -> float:
        wind = self.wind()
        speed = math.hypot(*wind)
        if not speed:
            return self.model.to_home(point)
        hx, hy, _ = self.model.home  # the wind in the face all the way home (the estimate has no direction)
        dx, dy = hx - point[0], hy - point[1]
        norm = math.hypot(dx, dy) or 1.0
        return self.model.to_home(point, (-dx / norm * speed, -dy / norm * speed))

    def _return_margin(self, who: Any) -> float | None:
        if who != "self":
            return None
        charge = self.memory.query("charge(battery, ?c)")
        point = self.position("self")
        if charge is None or point is None:
            return None
        return round(float(charge["?c"]) - self._worst_case(point), 1)

    def _rally_distance(self, who: Any) -> float | None:
        point = self.position(who)
        if point is None:
            return None
        places = [self.model.home, *self.rally_points]
        return round(min(math.hypot(point[0] - p[0], point[1] - p[1]) for p in places), 2)

    def _stopping_point(self, who: Any) -> Point | None:
        """Where the drone would stop if it braked now (its position plus v|v|/2a, horizontally)."""
        point = self.position(who) if who == "self" else None
        if point is None:
            return None
        vx, vy, _ = self.velocity()
        k = math.hypot(vx, vy) / (2.0 * self.model.max_acceleration)
        return (round(point[0] + vx * k, 2), round(point[1] + vy * k, 2), point[2])

    def _mission_time(self) -> float | None:
        return None if self.mission_started is None else round(self.now() - self.mission_started, 2)

    def nearest_rally(self, point: Point) -> Point:
        places = [self.model.home, *self.rally_points]
        return min(places, key=lambda p: math.hypot(point[0] - p[0], point[1] - p[1]))


__all__ = ["SafetyPredicates", "VehicleModel"]
