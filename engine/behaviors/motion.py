"""Motion behaviors (paper Table A.2) against the drone interface."""

from __future__ import annotations

MOTION_BEHAVIORS: list = []
