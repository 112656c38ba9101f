"""Local ENU meters from a home point <-> WGS84 geodetic coordinates (pymap3d, exact on the ellipsoid), and the
one written form of a geographic point, ``geo:LAT,LON,ALT``.

ENU is the drone interface's frame: x east, y north, z up, in meters from home. Geodetic points are
``(latitude deg, longitude deg, altitude m AMSL)``; altitudes are ellipsoidal as pymap3d computes them.

A geographic point in a mission (a behavior's argument, a port) is written ``geo:LAT,LON,ALT``: latitude and
longitude in degrees (WGS84), altitude in meters above home, as a ground station's relative altitude (the form of
RFC 5870's ``geo`` URI, whose altitude would be above the ellipsoid). :func:`geo_to_enu` places it from a home.
"""

from __future__ import annotations

import math
import re

Vector = tuple[float, float, float]
Geodetic = tuple[float, float, float]  # latitude (deg), longitude (deg), altitude (m)

GEO_PREFIX = "geo:"
# compiled on first use (re's cache): not at every start
_GEO = r"(?i)\s*geo:\s*([^,;\s]+)\s*,\s*([^,;\s]+)\s*(?:,\s*([^,;\s]+)\s*)?"

__all__ = ["GEO_PREFIX", "Geodetic", "enu_to_geodetic", "format_geo", "geo_to_enu", "geodetic_to_enu",
           "is_geo", "parse_geo", "parse_home", "valid_latitude_longitude"]


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


def valid_latitude_longitude(lat: float, lon: float) -> str | None:
    """Why ``(lat, lon)`` is no place on Earth (None when it is one)."""
    if not (math.isfinite(lat) and -90.0 <= lat <= 90.0):
        return f"latitude {lat:g} is not between -90 and 90"
    if not (math.isfinite(lon) and -180.0 <= lon <= 180.0):
        return f"longitude {lon:g} is not between -180 and 180"
    return None


def parse_home(text: str) -> tuple[float, float, float | None]:
    """``LAT,LON[,ALT]`` (degrees, meters AMSL) as a home point; the altitude is None when not given. Raises
    ValueError saying what is wrong."""
    try:
        numbers = [float(p) for p in text.split(",")]
    except ValueError:
        numbers = []
    if len(numbers) not in (2, 3) or not all(math.isfinite(n) for n in numbers):
        raise ValueError(f"{text!r} is not LATITUDE,LONGITUDE[,ALTITUDE] (degrees, meters AMSL)")
    why = valid_latitude_longitude(numbers[0], numbers[1])
    if why:
        raise ValueError(f"{text!r} is no place on Earth: {why}")
    return numbers[0], numbers[1], numbers[2] if len(numbers) == 3 else None


def is_geo(value: object) -> bool:
    """Whether ``value`` is a text written as a geographic point (``geo:...``), well formed or not."""
    return isinstance(value, str) and value.lstrip()[:4].lower() == GEO_PREFIX


def parse_geo(text: str) -> Geodetic:
    """``geo:LAT,LON[,ALT]`` as (latitude, longitude, altitude above home; 0 without ALT).

    Raises ValueError saying what is wrong (not the form, not numbers, not a place on Earth).
    """
    match = re.fullmatch(_GEO, text)
    if match is None:
        raise ValueError(f"{text!r} is not a geographic point (geo:LATITUDE,LONGITUDE,ALTITUDE)")
    try:
        lat, lon = float(match.group(1)), float(match.group(2))
        alt = float(match.group(3)) if match.group(3) is not None else 0.0
    except ValueError:
        raise ValueError(f"{text!r} is not a geographic point: its latitude, longitude and altitude are "
                         f"numbers") from None
    why = valid_latitude_longitude(lat, lon) or (None if math.isfinite(alt) else f"altitude {alt} is not finite")
    if why:
        raise ValueError(f"{text.strip()} is no place on Earth: {why}")
    return (lat, lon, alt)


def format_geo(lat: float, lon: float, alt: float) -> str:
    """The written form of a geographic point: ``geo:47.39773941,8.54559040,10`` (8 decimals: about 1 mm)."""
    height = f"{alt:.2f}".rstrip("0").rstrip(".")
    return f"geo:{lat:.8f},{lon:.8f},{'0' if height in ('-0', '') else height}"


def geo_to_enu(point: Geodetic, home: Geodetic) -> Vector:
    """ENU meters from ``home`` of a geographic point whose altitude is above home (the ``geo:`` form).

    East and north are measured on the ellipsoid at home's altitude; up is the point's own height above home,
    so a waypoint 1 km away at 10 m stays 10 m up (as an autopilot's relative altitude does).
    """
    east, north, _ = geodetic_to_enu((point[0], point[1], home[2]), home)
    return (east, north, float(point[2]))
