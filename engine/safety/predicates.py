"""The predicates safety rules read that are computed: ``battery_to_home``, ``return_margin`` (from the vehicle
model, :class:`aeroexec.drones.vehicle.VehicleModel`: distance, climb, speed, wind), ``rally_distance``,
``stopping_point`` and ``mission_time``; and how fast the return estimates can move, for the monitors' schedule.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from aeroexec.beliefs import Struct, Var
from aeroexec.drones.vehicle import VehicleModel

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # a memory is given: the predicates are registered with it
    from typing import Any

    from aeroexec.beliefs import BeliefMemory

Point = tuple[float, float, float]


class SafetyPredicates:
    """Registers the computed predicates of safety rules on a belief memory, reading the drone's position, charge
    and wind from the memory (what the rules see); ``stopping_point`` also reads this drone's velocity from
    ``velocity()`` (the telemetry's) and fleet mates' from ``velocity(dN, V)``."""

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

    # -- how fast what they compute can move (the monitors' schedule) ------------------------------------
    def home_cost_horizontal(self) -> float:
        """Percent of ``battery_to_home`` per meter flown horizontally, in the wind believed now."""
        return self.model.home_costs(math.hypot(*self.wind()))[0]

    def home_cost_vertical(self) -> float:
        """Percent of ``battery_to_home`` per meter up or down, in the wind believed now."""
        return self.model.home_costs(math.hypot(*self.wind()))[1]

    def home_cost(self) -> float:
        """Percent of ``battery_to_home`` per meter in any direction, in the wind believed now."""
        horizontal, vertical, _ = self.model.home_costs(math.hypot(*self.wind()))
        return max(horizontal, vertical)

    def home_step(self) -> float:
        """The step ``battery_to_home`` may take at once (rounding, the circle around home), in the wind now."""
        return 0.1 + self.model.home_costs(math.hypot(*self.wind()))[2]

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
        """Where a drone would stop if it braked now (its position plus v|v|/2a, horizontally, at the vehicle
        model's acceleration): this drone's from its telemetry's velocity, a fleet mate's from the ``velocity(dN,
        V)`` its fleet link shares (its position alone when it shares none)."""
        if who == "self":
            point = self.position("self")
            velocity = self.velocity() if point is not None else None
        elif type(who) is str:
            found = self.memory.query(Struct("position", (who, Var("?p"))))
            point = self.position(found["?p"]) if found else None
            velocity = (0.0, 0.0, 0.0)
            if point is not None and self.memory.accepts("velocity"):
                shared = self.memory.query(Struct("velocity", (who, Var("?v"))))
                value = shared["?v"] if shared else None
                if isinstance(value, tuple | list) and len(value) == 3 and all(type(v) in (int, float) for v in value):
                    velocity = value
        else:
            return None
        if point is None:
            return None
        vx, vy, _ = velocity
        k = math.hypot(vx, vy) / (2.0 * self.model.max_acceleration)
        return (round(point[0] + vx * k, 2), round(point[1] + vy * k, 2), point[2])

    def _mission_time(self) -> float | None:
        return None if self.mission_started is None else round(self.now() - self.mission_started, 2)

    def nearest_rally(self, point: Point) -> Point:
        places = [self.model.home, *self.rally_points]
        return min(places, key=lambda p: math.hypot(point[0] - p[0], point[1] - p[1]))


__all__ = ["SafetyPredicates"]
