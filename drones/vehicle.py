"""The vehicle model: what a flight costs in time and charge, from the vehicle's figures.

One model for every estimate made before or during a flight: verify's route of a mission (``trees/route.py``), a
live mission change's battery check (through that route), and the safety rules' ``battery_to_home`` and
``return_margin`` with their checks before flight (``engine/safety/``). Its figures are the simulated
multicopter's (:class:`aeroexec.drones.sim.SimConfig`: speeds, accelerations, climb, descent and landing rates,
the return altitude) and its drain is the simulated battery's own arithmetic
(:func:`aeroexec.drones.sim.vehicle.battery.drain_rate`: minutes of hover, extra drain with airspeed and climb, idle
on the ground), so an estimate and a simulated flight agree; a robot that is no simulator is estimated with the same
defaults.

A flight is made of legs as the simulator flies them: a take-off climbs at the take-off rate; GO_TO_POINT flies a
straight line, its horizontal part at the asked speed with time to accelerate and brake, its vertical part at the
climb or descent rate, whichever takes longer; a landing descends as the simulator and PX4 do (slowing between
the fast and the slow altitudes); a return home climbs to the return altitude, flies home at cruise speed and lands.
Wind slows a leg flown into it (the airspeed is at most the top speed) and drains as airspeed does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from aeroexec.drones.sim.config import SimConfig
from aeroexec.drones.sim.vehicle.battery import drain_rate

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

Point = tuple[float, float, float]
Wind = tuple[float, float]
CALM: Wind = (0.0, 0.0)
SETTLE = 4.0  # s a return spends arriving and starting its landing, beyond the leg and the descent
BRAKING_ABOVE = 0.5  # m: a horizontal leg longer than this accelerates and brakes


@dataclass(frozen=True)
class VehicleModel:
    """The flight and battery model of a vehicle with the figures of ``config``, and where its home is."""

    config: SimConfig = field(default_factory=SimConfig)
    home: Point = (0.0, 0.0, 0.0)

    @classmethod
    def of(cls, robot: Any) -> VehicleModel:
        """The model of ``robot``: its simulator's figures and start when it has them, the defaults otherwise."""
        config = getattr(robot, "config", None)
        if not isinstance(config, SimConfig):
            return cls()
        return cls(config, (float(config.start[0]), float(config.start[1]), 0.0))

    # -- the figures -----------------------------------------------------------------------------------------
    @property
    def cruise_speed(self) -> float:
        return self.config.cruise_speed

    @property
    def max_speed(self) -> float:
        return self.config.max_speed

    @property
    def max_climb_rate(self) -> float:
        return self.config.max_climb_rate

    @property
    def max_acceleration(self) -> float:
        return self.config.max_acceleration

    @property
    def return_altitude(self) -> float:
        return self.config.return_altitude

    @property
    def position_noise(self) -> float:
        """The standard deviation of reported positions (m)."""
        return self.config.position_noise_std

    @property
    def hover_rate(self) -> float:
        """Percent of charge per second hovering."""
        return 100.0 / (self.config.battery_hover_minutes * 60.0)

    @property
    def max_drain(self) -> float:
        """The most percent per second the battery can lose (full airspeed and climb)."""
        return self.drain(self.config.max_speed, self.config.max_climb_rate)

    def drain(self, airspeed: float, climb: float = 0.0, airborne: bool = True) -> float:
        """Percent per second at ``airspeed`` (horizontal) and ``climb`` (m/s, up); on the ground, armed."""
        return drain_rate(self.config, True, airborne, airspeed, climb)

    # -- legs ------------------------------------------------------------------------------------------------
    def fly(self, start: Sequence[float], end: Sequence[float], speed: float | None = None,
            wind: Wind = CALM) -> tuple[float, float]:
        """Seconds and percent of charge GO_TO_POINT takes from ``start`` to ``end`` at ``speed`` (default: cruise)
        horizontally, in ``wind``; infinite when the wind is too strong to make way against."""
        c = self.config
        dx, dy = end[0] - start[0], end[1] - start[1]
        horizontal = math.hypot(dx, dy)
        rise = end[2] - start[2]
        speed = min(max(speed if speed is not None else c.cruise_speed, 0.1), c.max_speed)
        cruise, air = 0.0, math.hypot(*wind)
        if horizontal > 1e-6:
            ground, air = self._track(dx / horizontal, dy / horizontal, speed, wind)
            if ground <= 1e-6:  # (a speed asked is at least 0.1 m/s: only the wind stops it)
                return math.inf, math.inf
            cruise = horizontal / ground + (ground / c.max_acceleration if horizontal > BRAKING_ABOVE else 0.0)
            air = air * (horizontal / ground) / cruise  # the mean airspeed, braking included
        vertical = abs(rise) / (c.max_climb_rate if rise > 0 else c.descent_rate)
        seconds = max(cruise, vertical)
        if seconds <= 0.0:
            return 0.0, 0.0
        if cruise < seconds:
            air = air * cruise / seconds if horizontal > 1e-6 else air
        return seconds, seconds * self.drain(air, rise / seconds)

    def take_off(self, altitude: float, wind: Wind = CALM) -> tuple[float, float]:
        """Seconds and percent a take-off to ``altitude`` above the ground takes (at the take-off climb rate)."""
        rate = self.config.climb_rate
        seconds = max(altitude, 0.0) / rate
        return seconds, seconds * self.drain(math.hypot(*wind), rate)

    def land(self, height: float, wind: Wind = CALM) -> tuple[float, float]:
        """Seconds and percent a landing from ``height`` takes."""
        seconds = self.descent_seconds(height)
        return seconds, seconds * self.drain(math.hypot(*wind))

    def hover(self, seconds: float, airborne: bool = True, wind: Wind = CALM) -> float:
        """Percent of charge ``seconds`` of hovering (or of standing armed on the ground) take."""
        return seconds * self.drain(math.hypot(*wind) if airborne else 0.0, 0.0, airborne)

    def descent_seconds(self, height: float) -> float:
        """Seconds to descend from ``height`` to the ground as a landing does (slowing down between the fast and
        the slow altitudes, the simulator's and PX4's MPC_LAND_ALT1/2)."""
        c = self.config
        low, high = c.land_slow_altitude, max(c.land_fast_altitude, c.land_slow_altitude)
        seconds = min(max(height, 0.0), low) / c.land_speed
        middle = min(max(height - low, 0.0), high - low)
        if middle > 0.0:
            v0, v1 = c.land_speed, c.descent_rate
            span = high - low
            if abs(v1 - v0) < 1e-9:
                seconds += middle / v0
            else:  # v(z) = v0 + (z - low) / span * (v1 - v0): the time is a logarithm
                seconds += span / (v1 - v0) * math.log((v0 + middle / span * (v1 - v0)) / v0)
        return seconds + max(height - high, 0.0) / c.descent_rate

    def _track(self, ux: float, uy: float, speed: float, wind: Wind) -> tuple[float, float]:
        """The ground speed along the unit track (ux, uy) asked at ``speed`` in ``wind``, and the airspeed flown."""
        ax, ay = ux * speed - wind[0], uy * speed - wind[1]
        air = math.hypot(ax, ay)
        top = self.config.max_speed
        if air <= top:
            return speed, air
        along = wind[0] * ux + wind[1] * uy  # the wind slows it: the ground speed at full airspeed
        cross = -wind[0] * uy + wind[1] * ux
        return along + math.sqrt(max(top * top - cross * cross, 0.0)), top

    # -- a return home ---------------------------------------------------------------------------------------
    def to_home(self, position: Sequence[float], wind: Wind = CALM, home: Point | None = None) -> float:
        """Percent of charge a return from ``position`` to ``home`` (default: the model's) takes: the climb to the
        return altitude, the flight home at cruise speed in ``wind``, and the landing."""
        home = home or self.home
        x, y, z = float(position[0]), float(position[1]), float(position[2])
        altitude = max(z, self.return_altitude) if math.hypot(x - home[0], y - home[1]) > 1.0 else z
        _, climb = self.fly((x, y, z), (x, y, altitude), wind=wind)
        _, travel = self.fly((x, y, altitude), (home[0], home[1], altitude), wind=wind)
        _, descend = self.land(altitude, wind)
        return climb + travel + descend + SETTLE * self.drain(math.hypot(*wind))

    def home_costs(self, wind: float = 0.0) -> tuple[float, float, float]:
        """How :meth:`to_home` against a wind of ``wind`` m/s can change as the vehicle moves: at most percent per
        meter flown horizontally (the flight home, into the wind), per meter up or down (the climb to the return
        altitude, the landing at its slowest), and the step it may take at once (crossing the circle of a meter
        around home, inside which it does not climb first; the time to accelerate and brake)."""
        c = self.config
        ground, air = self._track(1.0, 0.0, c.cruise_speed, (-wind, 0.0))
        if ground <= 0.1:
            return math.inf, math.inf, math.inf
        horizontal = self.hover_rate * (1.0 + 2.0 * c.battery_speed_drain * (air / c.max_speed) ** 2) / ground
        vertical = max(self.drain(wind, c.max_climb_rate) / c.max_climb_rate, self.drain(wind) / c.land_speed)
        height = c.return_altitude
        step = (height / c.max_climb_rate * self.drain(wind, c.max_climb_rate)
                + self.descent_seconds(height) * self.drain(wind) + ground / c.max_acceleration * self.drain(air))
        return horizontal, vertical, step


__all__ = ["SETTLE", "VehicleModel"]
