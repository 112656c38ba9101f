"""Frame conversions of the MAVSDK adapter: local ENU from home <-> WGS84 geodetic, NED <-> ENU, yaw <-> heading.

Geodetic conversions are :mod:`aeroexec.drones.geodesy`'s (pymap3d, exact on the WGS84 ellipsoid). Yaw is
the drone interface's: degrees, 0 = east, counterclockwise; heading is the autopilots': degrees, 0 = north,
clockwise.
"""

from __future__ import annotations

from aeroexec.drones.angles import wrap180 as wrap_degrees
from aeroexec.drones.geodesy import enu_to_geodetic, geodetic_to_enu

Vector = tuple[float, float, float]
Geodetic = tuple[float, float, float]  # latitude (deg), longitude (deg), altitude (m AMSL)

__all__ = [
    "enu_to_geodetic",
    "enu_to_ned",
    "geodetic_to_enu",
    "heading_to_yaw",
    "ned_to_enu",
    "wrap_degrees",
    "yaw_to_heading",
]


def ned_to_enu(north: float, east: float, down: float) -> Vector:
    """(east, north, up) of a NED vector."""
    return (east, north, -down)


def enu_to_ned(vector: Vector) -> Vector:
    """(north, east, down) of an ENU vector."""
    e, n, u = vector
    return (n, e, -u)


def heading_to_yaw(heading: float) -> float:
    """Compass heading (0 = north, clockwise) to ENU yaw (0 = east, counterclockwise) in (-180, 180]."""
    return wrap_degrees(90.0 - heading)


def yaw_to_heading(yaw: float) -> float:
    """ENU yaw to compass heading in [0, 360)."""
    return (90.0 - yaw) % 360.0
