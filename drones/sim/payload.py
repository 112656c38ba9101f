"""The simulated drone's payload: the items it carries, and where a released item falls and lands.

A released item falls from just below the drone with the drone's velocity, without drag, onto the top of the
obstacle under it or the ground; once it has landed it is an object of the world (an orange box unless named
otherwise), so the camera sees it and perception recognizes it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass

from aeroexec.drones.sim.shapes import Box, Cylinder
from aeroexec.drones.sim.world import World, WorldObject

Vector = tuple[float, float, float]

ITEM_SIZE = 0.3  # m: a dropped item is a cube of this side
ITEM_COLOR = "orange"
ITEM_SHAPE = "box"
HANG = 0.15  # m: the item hangs this far below the drone's center


@dataclass(frozen=True, slots=True)
class FallingItem:
    """An item on its way down: where and when it will land."""

    name: str
    landing: Vector  # where its center comes to rest
    lands_at: float  # simulation time


def surface_below(world: World, x: float, y: float, z: float) -> float:
    """The height of the highest surface under (x, y) that is below ``z``: an obstacle's top or the ground."""
    top = 0.0
    for obstacle in world.obstacles:
        if isinstance(obstacle, Box):
            (x0, y0, _), (x1, y1, height) = obstacle.lower, obstacle.upper
            over = x0 <= x <= x1 and y0 <= y <= y1
        elif isinstance(obstacle, Cylinder):
            height = obstacle.top
            over = math.hypot(x - obstacle.center[0], y - obstacle.center[1]) <= obstacle.radius
        else:
            continue
        if over and top < height <= z + 1e-6:
            top = height
    return top


def _fall_time(height: float, vz: float, gravity: float) -> float:
    """Seconds until something at ``height`` m above a surface, moving up at ``vz``, reaches it."""
    if height <= 0.0:
        return 0.0
    return (vz + math.sqrt(vz * vz + 2.0 * gravity * height)) / gravity


class PayloadBay:
    """What the drone carries, and the items falling after a release."""

    def __init__(self, items: Iterable[str] = ()) -> None:
        self.carried: list[str] = list(items)
        self.falling: list[FallingItem] = []

    def release(self, world: World, position: Vector, velocity: Vector, now: float,
                gravity: float = 9.81) -> FallingItem | None:
        """Let go of the first item carried; None when nothing is carried."""
        if not self.carried:
            return None
        name = self.carried.pop(0)
        x, y, z = position
        z = max(z - HANG, 0.0)
        vx, vy, vz = velocity
        half = ITEM_SIZE / 2.0
        surface = surface_below(world, x, y, z)
        t = _fall_time(z - half - surface, vz, gravity)
        for _ in range(2):  # the drift may carry it over another surface: settle on the one it lands on
            lx, ly = x + vx * t, y + vy * t
            surface = surface_below(world, lx, ly, z)
            t = _fall_time(z - half - surface, vz, gravity)
        item = FallingItem(name, (x + vx * t, y + vy * t, surface + half), now + t)
        self.falling.append(item)
        return item

    def settle(self, world: World, now: float) -> tuple[World, list[WorldObject]]:
        """The world with the items that have landed by ``now`` added as objects, and those objects."""
        landed = [item for item in self.falling if item.lands_at <= now + 1e-9]
        if not landed:
            return world, []
        self.falling = [item for item in self.falling if item.lands_at > now + 1e-9]
        taken = {o.name for o in world.objects} | {o.name for o in world.obstacles} | {m.name for m in world.markers}
        objects = []
        for item in landed:
            name, count = item.name, 1
            while name in taken:
                count += 1
                name = f"{item.name}_{count}"
            taken.add(name)
            x, y, z = item.landing
            objects.append(WorldObject(name, ITEM_COLOR, ITEM_SHAPE, (round(x, 3), round(y, 3), round(z, 3))))
        return dataclasses.replace(world, objects=world.objects + tuple(objects)), objects


__all__ = ["FallingItem", "PayloadBay", "surface_below"]
