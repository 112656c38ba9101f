"""VERIFY (paper Table A.3): a deliberative behavior that checks one condition now; its result is true or false.

- MARKER_IS_OBSERVED=N: a marker with code N is visible now (``code(M, N), visible(M)``; something must be
  recognizing markers, e.g. PAY_ATTENTION_TO_VISUAL_MARKERS or a marker localization);
- HOVERING=true|false: whether the drone is hovering (``flight_state(self, hovering)``) is as given;
- CURRENT_SPEED=V: the drone's current speed (telemetry) is at least V m/s;
- OBSTACLE_DISTANCE=D: the nearest obstacle is at least D m from the drone (the obstacle map; without one,
  nothing is known to be near and the answer is true);
- VOICE_COMMAND=TEXT: the operator channel's last voice command is TEXT (case and surrounding spaces
  ignored); without a channel, or with no voice command heard, false.
"""

from __future__ import annotations

from typing import Any

from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess


def last_voice_command(operator: Any) -> str | None:
    """The last voice command an operator channel heard (``last_voice_command`` attribute or method), if any."""
    heard = getattr(operator, "last_voice_command", None)
    if callable(heard):
        heard = heard()
    return None if heard is None else str(heard)


class Verify(BehaviorProcess):
    """VERIFY: the result is True when the condition given holds now, False otherwise."""

    behavior = "VERIFY"

    def on_start(self) -> None:
        condition, value = next((k, v) for k, v in self.arguments.items() if v is not None)
        self.result = bool(getattr(self, "_" + condition.lower())(value))
        self.context.log.record("verified", self.name, f"{condition}={value}: {str(self.result).lower()}",
                                condition=condition, value=value, result=self.result)

    def on_run(self) -> Outcome | None:
        return Outcome.GOAL_ACHIEVED

    def _marker_is_observed(self, code: int) -> bool:
        return self.memory.holds(f"code(?M, {int(code)}), visible(?M)")

    def _hovering(self, expected: bool) -> bool:
        return self.memory.holds("flight_state(self, hovering)") == bool(expected)

    def _current_speed(self, speed: float) -> bool:
        return self.telemetry().speed >= float(speed)

    def _obstacle_distance(self, distance: float) -> bool:
        obstacles = self.context.obstacles
        if obstacles is None:
            return True
        return obstacles.distance_to_obstacle(tuple(self.telemetry().position)) >= float(distance) - 1e-9

    def _voice_command(self, text: str) -> bool:
        heard = last_voice_command(self.context.operator)
        return heard is not None and heard.strip().casefold() == str(text).strip().casefold()


VERIFY_BEHAVIORS: list[type[BehaviorProcess]] = [Verify]
