"""Contact of the simulated multicopter with the world's moving platform and objects.

The platform's deck (a disc of ``Platform.deck_radius`` around ``Platform.position(t)``, at the path's
height) is a surface: a drone descending onto it from above touches down on it, then rides along (its
position follows the deck) until it takes off. Objects are small things, not obstacles: the drone
*touches* one when its center comes within ``SimConfig.touch_distance`` of the object's position.
"""

from __future__ import annotations

import math

from aeroexec.drones.sim.world import World

Vector = tuple[float, float, float]

DECK_CONTACT = 0.02  # m: at or below this height above the deck, descending, the drone is on it
TOUCH_RELEASE = 0.2  # m: a touch ends once the drone is this much farther than the touch distance


class Contacts:
    """The deck the drone stands on (if any) and the things it touches now."""

    def __init__(self, world: World, touch_distance: float) -> None:
        self.world = world
        self.touch_distance = touch_distance
        self.riding: tuple[float, float] | None = None  # offset from the deck's center while landed on it
        self.touching: set[str] = set()
        self._platform_at: tuple[float, Vector] | None = None  # the platform's position at the last time asked
        self._objects = [(o.name, o.position) for o in world.objects]  # they do not move

    def _platform(self, t: float) -> Vector:
        """Where the platform is at ``t`` (asked twice per substep: computed once)."""
        if self._platform_at is None or self._platform_at[0] != t:
            self._platform_at = (t, self.world.platform.position(t))  # type: ignore[union-attr]
        return self._platform_at[1]

    def deck_below(self, position: Vector, t: float, previous_z: float) -> float | None:
        """The deck's height when ``position`` is over the deck and came from above it (``previous_z``)."""
        platform = self.world.platform
        if platform is None:
            return None
        cx, cy, cz = self._platform(t)
        if math.hypot(position[0] - cx, position[1] - cy) > platform.deck_radius:
            return None
        return cz if previous_z >= cz - DECK_CONTACT else None

    def board(self, position: Vector, t: float) -> tuple[Vector, Vector]:
        """Land on the deck at ``position``: (where the drone stands, its velocity, the deck's)."""
        platform = self.world.platform
        assert platform is not None
        cx, cy, cz = platform.position(t)
        self.riding = (position[0] - cx, position[1] - cy)
        return (position[0], position[1], cz), platform.velocity(t)

    def ride(self, t: float) -> tuple[Vector, Vector] | None:
        """Where a drone landed on the deck is at ``t`` and how fast it moves; None when it is not on it."""
        platform = self.world.platform
        if self.riding is None or platform is None:
            return None
        cx, cy, cz = platform.position(t)
        return (cx + self.riding[0], cy + self.riding[1], cz), platform.velocity(t)

    def leave(self) -> None:
        """The drone left the deck (took off, crashed)."""
        self.riding = None

    def touches(self, position: Vector, t: float) -> list[tuple[str, Vector]]:
        """The objects (and the platform) the drone has just come to touch, with their positions."""
        things = list(self._objects)
        if self.world.platform is not None:
            things.append((self.world.platform.name, self._platform(t)))
        new = []
        for name, where in things:
            distance = math.dist(position, where)
            if name in self.touching:
                if distance > self.touch_distance + TOUCH_RELEASE:
                    self.touching.discard(name)
            elif distance <= self.touch_distance:
                self.touching.add(name)
                new.append((name, where))
        return new
