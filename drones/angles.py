"""Angles in degrees as the drone interface uses them: yaw 0 = east, counterclockwise, in (-180, 180]."""

from __future__ import annotations

import math


def wrap180(angle: float) -> float:
    """The same direction as ``angle`` (degrees), in (-180, 180]."""
    if -180.0 < angle <= 180.0:  # already there (what the arithmetic below would give, exactly)
        return angle
    angle = math.fmod(angle, 360.0)
    if angle <= -180.0:
        angle += 360.0
    elif angle > 180.0:
        angle -= 360.0
    return angle
