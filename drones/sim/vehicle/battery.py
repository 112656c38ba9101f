"""The simulated battery: charge drained by time and motion, and a LiPo voltage curve.

Capacity is given as minutes of hover; moving fast and climbing drain more, idling armed on the ground less.
"""

from __future__ import annotations

import bisect

from aeroexec.drones.sim.config import SimConfig

# Resting voltage of one LiPo cell by state of charge (percent), a common 4S-pack discharge table.
_CURVE_PERCENT = (0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60, 65, 70, 75, 80, 85, 90, 95, 100)
_CURVE_VOLTS = (3.27, 3.61, 3.69, 3.71, 3.73, 3.75, 3.77, 3.79, 3.80, 3.82, 3.84,
                3.85, 3.87, 3.91, 3.95, 3.98, 4.02, 4.08, 4.11, 4.15, 4.20)


def cell_voltage(percent: float) -> float:
    """Resting voltage of one LiPo cell at ``percent`` charge (linear between table points)."""
    p = min(max(percent, 0.0), 100.0)
    i = min(bisect.bisect_right(_CURVE_PERCENT, p), len(_CURVE_PERCENT) - 1)
    p0, p1 = _CURVE_PERCENT[i - 1], _CURVE_PERCENT[i]
    v0, v1 = _CURVE_VOLTS[i - 1], _CURVE_VOLTS[i]
    return v0 + (v1 - v0) * (p - p0) / (p1 - p0)


def drain_rate(config: SimConfig, armed: bool, airborne: bool, horizontal_speed: float, climb: float) -> float:
    """Percent per second a battery with ``config``'s figures loses in the given state of the motors and motion
    (the vehicle model's estimates use it too: ``aeroexec.drones.vehicle``)."""
    if not armed:
        return 0.0
    hover = 100.0 / (config.battery_hover_minutes * 60.0)
    if not airborne:
        return hover * config.battery_idle_drain
    return hover * (1.0 + config.battery_speed_drain * (horizontal_speed / config.max_speed) ** 2
                    + config.battery_climb_drain * max(climb, 0.0) / config.max_climb_rate)


class Battery:
    """State of charge in percent, drained by :meth:`drain` each simulation step."""

    def __init__(self, config: SimConfig) -> None:
        self.config = config
        self.percent = config.initial_battery_percent
        self._hover_rate = 100.0 / (config.battery_hover_minutes * 60.0)  # percent per second

    @property
    def voltage(self) -> float:
        return cell_voltage(self.percent) * self.config.battery_cells

    def drain_rate(self, armed: bool, airborne: bool, horizontal_speed: float, climb: float) -> float:
        """Percent per second for the given state of the motors and motion."""
        return drain_rate(self.config, armed, airborne, horizontal_speed, climb)

    def drain(self, dt: float, armed: bool, airborne: bool, horizontal_speed: float, climb: float) -> None:
        self.percent = max(self.percent - dt * self.drain_rate(armed, airborne, horizontal_speed, climb), 0.0)

    def drain_flying(self, dt: float, horizontal_speed: float, climb: float) -> None:
        """:meth:`drain` armed and airborne (every substep of a flight): :func:`drain_rate`'s arithmetic in one
        call."""
        c = self.config
        load = (1.0 + c.battery_speed_drain * (horizontal_speed / c.max_speed) ** 2
                + c.battery_climb_drain * max(climb, 0.0) / c.max_climb_rate)
        self.percent = max(self.percent - dt * (self._hover_rate * load), 0.0)
