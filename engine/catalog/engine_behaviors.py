"""The behaviors the engine requests by itself, named once: the landing that ends a run, the flight and hover of a
safety rule's contingency, the hover that holds a paused robot, the steps that put a resumed drone back. A catalog
for another robot names its own (``ExecutionSettings.hold_behavior``); these are the aerial catalog's names."""

from __future__ import annotations

TAKE_OFF = "TAKE_OFF"
GO_TO_POINT = "GO_TO_POINT"
KEEP_HOVERING = "KEEP_HOVERING"
LAND = "LAND"

__all__ = ["GO_TO_POINT", "KEEP_HOVERING", "LAND", "TAKE_OFF"]
