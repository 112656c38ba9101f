"""Activation conditions of recurrent behaviors (paper Appendix A): distance to a point, delay, yaw range.

A recurrent behavior requested with conditions is accepted at once but starts
working only when all of them hold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

Vector = tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class ActivationConditions:
    """Start only within ``distance`` meters of ``point``, after ``delay`` seconds, with yaw in ``yaw_range``."""

    point: Vector | None = None
    distance: float | None = None
    delay: float | None = None
    yaw_range: tuple[float, float] | None = None  # degrees, min and max (may wrap through 180)

    def __post_init__(self) -> None:
        if (self.point is None) != (self.distance is None):
            raise ValueError("a distance condition needs both a point and a distance")
        if self.distance is not None and self.distance <= 0:
            raise ValueError(f"the distance of an activation condition must be positive, not {self.distance}")
        if self.delay is not None and self.delay < 0:
            raise ValueError(f"the delay of an activation condition cannot be negative, not {self.delay}")

    def __str__(self) -> str:
        parts = []
        if self.delay is not None:
            parts.append(f"{self.delay:g} s after the request")
        if self.point is not None:
            parts.append(f"within {self.distance:g} m of {tuple(self.point)}")
        if self.yaw_range is not None:
            parts.append(f"yaw between {self.yaw_range[0]:g} and {self.yaw_range[1]:g} degrees")
        return "starts " + ", ".join(parts)

    def hold(self, context: Any, requested_at: float | None = None) -> bool:
        """True when every condition holds now (``context`` is the behavior context)."""
        telemetry = context.drone.telemetry()
        if self.delay is not None and context.now() - (requested_at or 0.0) < self.delay:
            return False
        if self.point is not None and math.dist(telemetry.position, self.point) > self.distance:
            return False
        return self.yaw_range is None or yaw_within(telemetry.yaw, *self.yaw_range)


def yaw_within(yaw: float, low: float, high: float) -> bool:
    """True when ``yaw`` lies on the counterclockwise arc from ``low`` to ``high`` (degrees)."""
    span = (high - low) % 360.0
    return (yaw - low) % 360.0 <= span or math.isclose(span, 0.0) and math.isclose((yaw - low) % 360.0, 0.0)
