"""``rclpy.callback_groups`` as a mission sees it: callback groups as data. aeroexec runs a node's callbacks one at
a time on the spinning thread (:mod:`.executors`), which every group's rule allows: a mutually exclusive group runs
one of its callbacks at a time, a reentrant one may run them in parallel (it is not required to)."""

from __future__ import annotations

from typing import Any


class CallbackGroup:
    """A group of a node's callbacks (its timers'; subscriptions and services need a ROS 2 graph)."""

    def __init__(self) -> None:
        self.entities: list[Any] = []

    def add_entity(self, entity: Any) -> None:
        self.entities.append(entity)

    def has_entity(self, entity: Any) -> bool:
        return any(e is entity for e in self.entities)

    def can_execute(self, entity: Any) -> bool:
        return True  # one callback at a time, always


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """One callback of the group at a time."""


class ReentrantCallbackGroup(CallbackGroup):
    """The group's callbacks may run in parallel."""


__all__ = ["CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"]
