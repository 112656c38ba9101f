"""Open fields: worlds generated around a place, for missions planned on a map rather than in a world file.

:func:`open_field` makes a flat, obstacle-free world at a home point whose bounds are the places a mission names
(ENU meters from that home) plus a margin that grows with the mission's size, with the mission's geofence as the
world's fences; :func:`field_at` a square field of a given reach around a home (``aeroexec sim --home``);
:func:`field_of` the field an event log's first record describes (its home and bounds), for reports and replays.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from aeroexec.drones.geodesy import Geodetic
from aeroexec.drones.sim.geofence import Fence
from aeroexec.drones.sim.world import Bounds, World

MARGIN = 30.0  # m around a mission's places, at the least
MARGIN_SHARE = 0.1  # ... or this share of the mission's size
HEADROOM = 10.0  # m above its highest place, at the least (and the simulated drone's 10 m return altitude)


def _name(home: Geodetic) -> str:
    return f"open field at {home[0]:.5f}, {home[1]:.5f}"


def open_field(home: Geodetic, places: Iterable[Sequence[float]], fences: Sequence[Fence] = (),
               payload: tuple[str, ...] = (), name: str | None = None) -> World:
    """A flat world at ``home`` around ``places`` (ENU points; home is always one), fenced by ``fences``."""
    points = [(0.0, 0.0, 0.0), *((float(p[0]), float(p[1]), float(p[2]) if len(p) > 2 else 0.0) for p in places)]
    for fence in fences:
        if fence.center is not None:
            (x, y), r = fence.center, fence.radius
            points += [(x - r, y - r, 0.0), (x + r, y + r, 0.0)] if fence.inclusion else []
        elif fence.inclusion:
            points += [(x, y, 0.0) for x, y in fence.vertices]
    xs, ys, zs = ([p[i] for p in points] for i in range(3))
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    margin = max(MARGIN, MARGIN_SHARE * size)
    top = max(zs)
    bounds = Bounds((min(xs) - margin, min(ys) - margin, min(0.0, min(zs))),
                    (max(xs) + margin, max(ys) + margin, max(top + max(HEADROOM, MARGIN_SHARE * top), 2 * HEADROOM)))
    return World(home=home, bounds=bounds, fences=tuple(fences), payload=payload, name=name or _name(home))


def field_of(home: Sequence[float], bounds: Sequence[Sequence[float]]) -> World:
    """The open field an event log's first record describes (its ``home`` and ``bounds``): what a report or a
    replay draws a flight at real scale in when the flight's world was generated, not read from a file."""
    lower, upper = (tuple(float(v) for v in corner) for corner in bounds)
    point = (float(home[0]), float(home[1]), float(home[2]))
    return World(home=point, bounds=Bounds(lower, upper), name=_name(point))  # type: ignore[arg-type]


def field_at(home: Geodetic, reach: float, ceiling: float) -> World:
    """A flat world at ``home``: ``reach`` meters around it, ``ceiling`` meters high."""
    return World(home=home, bounds=Bounds((-reach, -reach, 0.0), (reach, reach, ceiling)), name=_name(home))


__all__ = ["field_at", "field_of", "open_field"]
