"""Places written ``geo:LAT,LON,ALT`` in a request, placed in the drone's frame (ENU meters from home).

A behavior's place arguments (``allowed_values: WORLD`` in the catalog: COORDINATES, DESTINATION, the points to look
at, PATH, REGION) take geographic points. The specialist places them from the home it knows (the world's when a
mission is verified; the flying drone's own home in flight, so a plan flies to its latitudes and longitudes
whatever the vehicle's home), before their values are checked.
"""

from __future__ import annotations

from collections.abc import Mapping

from aeroexec.drones.geodesy import Geodetic, geo_to_enu, is_geo, parse_geo
from aeroexec.engine.catalog.descriptors import BehaviorDescriptor

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

def _placed(value: Any, home: Geodetic) -> Any:
    if is_geo(value):
        try:
            east, north, up = geo_to_enu(parse_geo(value), home)
        except ValueError:
            return value  # malformed: the argument's check says why
        return (round(east, 3), round(north, 3), round(up, 3))
    return value


def localize(descriptor: BehaviorDescriptor, arguments: Mapping[str, Any], home: Geodetic | None) -> dict[str, Any]:
    """``arguments`` with every ``geo:`` place of a place argument as ENU meters from ``home`` (unchanged without
    a home)."""
    placed = dict(arguments)
    if home is None:
        return placed
    for name, value in arguments.items():
        argument = descriptor.arguments.get(name)
        if argument is None or not argument.is_place:
            continue
        if argument.value_type == "PATH" and isinstance(value, list | tuple):
            placed[name] = tuple(_placed(point, home) for point in value)
        else:
            placed[name] = _placed(value, home)
    return placed


__all__ = ["localize"]
