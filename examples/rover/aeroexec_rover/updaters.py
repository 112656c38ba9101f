"""The rover's beliefs about itself: position(self, (x, y)), heading(self, H), docked(self, yes|no),
bumper(self, pressed|free), motion(self, docked|still|driving), charge(battery, N), battery_level(self, L)."""

from __future__ import annotations

import math

from aeroexec.beliefs import BeliefMemory, BeliefUpdater, Struct

from aeroexec_rover.rover import SimulatedRover

PREDICATES = {"position": 2, "heading": 2, "docked": 2, "bumper": 2, "motion": 2, "charge": 2, "battery_level": 2}


def battery_level(percent: float) -> str:
    return "low" if percent < 20 else "medium" if percent < 50 else "high"


class RoverUpdater(BeliefUpdater):
    """The rover's own state, from its telemetry and sensors, every ``period`` seconds."""

    def __init__(self, rover: SimulatedRover, period: float = 0.1) -> None:
        super().__init__("rover", period)
        self.rover = rover

    def update(self, memory: BeliefMemory, now: float) -> None:
        t = self.rover.telemetry()
        x, y, _ = t.position
        motion = t.flight_mode.lower()  # DOCKED, STILL, DRIVING
        for fact in (Struct("position", ("self", (round(x, 2), round(y, 2)))),
                     Struct("heading", ("self", round(t.yaw))),
                     Struct("docked", ("self", "yes" if motion == "docked" else "no")),
                     Struct("bumper", ("self", "pressed" if self.rover.bumper else "free")),
                     Struct("motion", ("self", motion)),
                     Struct("charge", ("battery", int(math.floor(t.battery_percent)))),
                     Struct("battery_level", ("self", battery_level(t.battery_percent)))):
            memory.add(fact)
