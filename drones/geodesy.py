"""Local ENU meters from a home point <-> WGS84 geodetic coordinates (pymap3d, exact on the ellipsoid).

ENU is the drone interface's frame: x east, y north, z up, in meters from home. Geodetic points are
``(latitude deg, longitude deg, altitude m AMSL)``; altitudes are ellipsoidal as pymap3d computes them.
"""

from __future__ import annotations

Vector = tuple[float, float, float]
Geodetic = tuple[float, float, float]  # latitude (deg), longitude (deg), altitude (m)

__all__ = ["Geodetic", "enu_to_geodetic", "geodetic_to_enu"]


def enu_to_geodetic(enu: Vector, home: Geodetic) -> Geodetic:
    """The geodetic point ``enu`` meters (east, north, up) from ``home``."""
    import pymap3d  # here: it brings numpy, which most commands never need

    east, north, up = enu
    lat0, lon0, alt0 = home
    lat, lon, alt = pymap3d.enu2geodetic(east, north, up, lat0, lon0, alt0)
    return (float(lat), float(lon), float(alt))


def geodetic_to_enu(point: Geodetic, home: Geodetic) -> Vector:
    """(east, north, up) meters of the geodetic ``point`` from ``home``."""
    import pymap3d

    lat, lon, alt = point
    lat0, lon0, alt0 = home
    east, north, up = pymap3d.geodetic2enu(lat, lon, alt, lat0, lon0, alt0)
    return (float(east), float(north), float(up))
