"""Contact of the simulated multicopter with the world's moving platform and objects.

The platform's deck (a disc of ``Platform.deck_radius`` around ``Platform.position(t)``, at the path's
height) is a surface: a drone descending onto it from above touches down on it, then rides along (its
position follows the deck) until it takes off. Objects are small things, not obstacles: the drone
*touches* one when its center comes within ``SimConfig.touch_distance`` of the object's position.

Checked every substep, so with a broad phase: the platform never leaves the box of its path's points and the
objects do not move, so a drone far from that box is over no deck and touches nothing there, and only the
objects of the grid column the drone is in are measured. The answers are those of measuring everything.
"""

from __future__ import annotations

import math

from aeroexec.drones.sim.world import World

Vector = tuple[float, float, float]
Box = tuple[float, float, float, float, float, float]  # lower x, y, z, upper x, y, z

DECK_CONTACT = 0.02  # m: at or below this height above the deck, descending, the drone is on it
TOUCH_RELEASE = 0.2  # m: a touch ends once the drone is this much farther than the touch distance
_CELL = 4.0  # m: the side of the objects' grid columns
_SLACK = 1e-6  # m: added to the broad phase's margins, against rounding
_NOWHERE: Box = (math.inf, math.inf, math.inf, -math.inf, -math.inf, -math.inf)
_EVERYWHERE: Box = (-math.inf, -math.inf, -math.inf, math.inf, math.inf, math.inf)


class Contacts:
    """The deck the drone stands on (if any) and the things it touches now."""

    def __init__(self, world: World, touch_distance: float) -> None:
        self.world = world
        self.touch_distance = touch_distance
        self.riding: tuple[float, float] | None = None  # offset from the deck's center while landed on it
        self.touching: set[str] = set()
        self._platform_at: tuple[float, Vector] | None = None  # the platform's position at the last time asked
        self._objects = [(o.name, o.position) for o in world.objects]  # they do not move
        reach = touch_distance + TOUCH_RELEASE + _SLACK  # farther from a thing than this: not touching it
        self._columns = _columns(self._objects, reach)
        platform = world.platform
        names = [name for name, _ in self._objects] + ([platform.name] if platform is not None else [])
        self._indexed = len(set(names)) == len(names)  # touches are known by name: the broad phase needs them unique
        self.touchables = bool(names)  # False: nothing to touch, ever (``touches`` is always empty)
        self._deck_top: float | None = None
        self._deck_box = self._touch_box = _NOWHERE
        if platform is not None and not platform.path:  # a platform nowhere: no broad phase (as before it)
            self._deck_top, self._deck_box = math.inf, _EVERYWHERE
            self._touch_box = _EVERYWHERE
        elif platform is not None:
            points = [tuple(float(v) for v in p) for p in platform.path]
            low = [min(p[i] for p in points) for i in range(3)]
            high = [max(p[i] for p in points) for i in range(3)]
            self._deck_top = high[2]
            deck = platform.deck_radius + _SLACK  # horizontally farther from the path's box: over no deck
            self._deck_box = (low[0] - deck, low[1] - deck, -math.inf, high[0] + deck, high[1] + deck, math.inf)
            self._touch_box = (low[0] - reach, low[1] - reach, low[2] - reach,
                               high[0] + reach, high[1] + reach, high[2] + reach)

    def _platform(self, t: float) -> Vector:
        """Where the platform is at ``t`` (asked twice per substep: computed once)."""
        if self._platform_at is None or self._platform_at[0] != t:
            self._platform_at = (t, self.world.platform.position(t))  # type: ignore[union-attr]
        return self._platform_at[1]

    def deck_top(self) -> float | None:
        """The highest the platform's deck ever is (None without a platform): above it, no deck is reached."""
        return self._deck_top

    def deck_below(self, position: Vector, t: float, previous_z: float) -> float | None:
        """The deck's height when ``position`` is over the deck and came from above it (``previous_z``)."""
        platform = self.world.platform
        if platform is None or not _inside(position, self._deck_box):
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
        platform = self.world.platform
        if not self._indexed:  # names shared: measure everything, in the world's order
            things = list(self._objects)
            if platform is not None:
                things.append((platform.name, self._platform(t)))
            return self._touch(position, things)
        near = self._columns.get((math.floor(position[0] / _CELL), math.floor(position[1] / _CELL)))
        platform_near = platform is not None and _inside(position, self._touch_box)
        if near is None and not platform_near:  # nothing within reach: any touch has ended
            if self.touching:
                self.touching.clear()
            return []
        things = list(near or ())
        if platform_near:
            things.append((platform.name, self._platform(t)))  # type: ignore[union-attr]
        if self.touching:  # a thing touched that is not near is out of reach: that touch has ended
            self.touching.intersection_update([name for name, _ in things])
        return self._touch(position, things)

    def _touch(self, position: Vector, things: list[tuple[str, Vector]]) -> list[tuple[str, Vector]]:
        """Measure ``things`` (in order): the ones newly touched; touches that ended are forgotten."""
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


def _inside(position: Vector, box: Box) -> bool:
    x, y, z = position
    return box[0] <= x <= box[3] and box[1] <= y <= box[4] and box[2] <= z <= box[5]


def _columns(objects: list[tuple[str, Vector]], reach: float) -> dict[tuple[int, int], tuple[tuple[str, Vector], ...]]:
    """The objects within ``reach`` (by their box) of each grid column, in the world's order."""
    columns: dict[tuple[int, int], list[tuple[str, Vector]]] = {}
    for name, where in objects:
        x, y = where[0], where[1]
        for i in range(math.floor((x - reach) / _CELL), math.floor((x + reach) / _CELL) + 1):
            for j in range(math.floor((y - reach) / _CELL), math.floor((y + reach) / _CELL) + 1):
                columns.setdefault((i, j), []).append((name, where))
    return {key: tuple(found) for key, found in columns.items()}
