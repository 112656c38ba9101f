"""The items of a QGroundControl survey, corridor scan or structure scan computed from the complex item itself, for
plans saved without the items QGroundControl generated (``TransectStyleComplexItem.Items``).

They are laid out as QGroundControl lays them out: positions projected on the plane tangent at the polygon's first
vertex (azimuthal equidistant on a 6371 km sphere, QGroundControl's and PX4's local projection); a survey sweeps
parallel lines ``AdjustedFootprintSide`` apart across the polygon turned by its ``angle`` (0: north-south lines,
clockwise), keeps each line's longest chord in the polygon, flies them back and forth from the entry corner and
extends each by ``TurnAroundDistance``; a corridor scan flies offsets of its polyline across ``CorridorWidth``; a
structure scan circles the structure's polygon, pushed out by the camera's distance, once per layer. The camera
triggers every ``AdjustedFootprintFrontal`` meters along each transect (DO_SET_CAM_TRIGG_DIST).
"""

from __future__ import annotations

import math
from typing import Any

from aeroexec.drones.geodesy import Geodetic
from aeroexec.trees.items.model import number

EARTH_RADIUS = 6371000.0  # m: QGroundControl's and PX4's sphere for local projections
WAYPOINT, TRIGGER = 16, 206
Point = tuple[float, float]  # east, north (m) on the tangent plane
Item = tuple[int, int, tuple[float, ...]]  # command, frame, seven params


class TransectError(ValueError):
    """A complex item whose items cannot be computed; ``node`` is the JSON object at fault (for its line)."""

    def __init__(self, message: str, node: Any = None) -> None:
        super().__init__(message)
        self.node = node


class _Plane:
    """The azimuthal equidistant projection around ``origin`` (latitude, longitude)."""

    def __init__(self, origin: tuple[float, float]) -> None:
        self.lat0, self.lon0 = math.radians(origin[0]), math.radians(origin[1])

    def to_plane(self, lat: float, lon: float) -> Point:
        la, lo = math.radians(lat), math.radians(lon)
        cos_c = math.sin(self.lat0) * math.sin(la) + math.cos(self.lat0) * math.cos(la) * math.cos(lo - self.lon0)
        c = math.acos(max(-1.0, min(1.0, cos_c)))
        k = 1.0 if abs(c) < 1e-12 else c / math.sin(c)
        north = k * (math.cos(self.lat0) * math.sin(la) - math.sin(self.lat0) * math.cos(la) * math.cos(lo - self.lon0))
        east = k * math.cos(la) * math.sin(lo - self.lon0)
        return (east * EARTH_RADIUS, north * EARTH_RADIUS)

    def to_geo(self, point: Point) -> tuple[float, float]:
        x, y = point[1] / EARTH_RADIUS, point[0] / EARTH_RADIUS  # north, east in radians
        c = math.hypot(x, y)
        if c < 1e-15:
            return (math.degrees(self.lat0), math.degrees(self.lon0))
        sin_c, cos_c = math.sin(c), math.cos(c)
        lat = math.asin(cos_c * math.sin(self.lat0) + x * sin_c * math.cos(self.lat0) / c)
        lon = self.lon0 + math.atan2(y * sin_c, c * math.cos(self.lat0) * cos_c - x * math.sin(self.lat0) * sin_c)
        return (math.degrees(lat), math.degrees(lon))


def _polygon(item: dict, key: str, minimum: int) -> list[tuple[float, float]]:
    points = item.get(key)
    found = []
    for point in points if isinstance(points, list) else []:
        if isinstance(point, list) and len(point) >= 2:
            lat, lon = number(point[0]), number(point[1])
            if not (math.isnan(lat) or math.isnan(lon)) and -90 <= lat <= 90 and -180 <= lon <= 180:
                found.append((lat, lon))
                continue
        raise TransectError(f"a point of its {key} is [latitude, longitude], not {point!r}", item)
    if len(found) < minimum:
        raise TransectError(f"its {key} needs {minimum} or more points, not {len(found)}", item)
    return found


def _camera(item: dict) -> tuple[dict, float, int]:
    """The camera settings (of the transect style when there is one), the altitude and its MAV_FRAME."""
    style = item.get("TransectStyleComplexItem")
    holder = style if isinstance(style, dict) else item
    camera = holder.get("CameraCalc")
    if not isinstance(camera, dict):
        raise TransectError("it needs its CameraCalc (the camera's distance and footprint)", item)
    altitude = number(camera.get("DistanceToSurface"))
    if not altitude > 0:
        raise TransectError("its CameraCalc needs a DistanceToSurface above 0", camera)
    mode = camera.get("DistanceMode")
    absolute = camera.get("DistanceToSurfaceRelative") is False or mode == 2
    return camera, altitude, 0 if absolute else (10 if mode == 3 else 3)


def _spacing(camera: dict, key: str) -> float:
    value = number(camera.get(key))
    if not value > 0:
        raise TransectError(f"its CameraCalc needs an {key} above 0 (meters between transects or photos)", camera)
    return value


def _rotate(point: Point, origin: Point, angle: float) -> Point:
    """``point`` turned ``angle`` degrees clockwise about ``origin`` (x east, y north)."""
    r = math.radians(-angle)
    dx, dy = point[0] - origin[0], point[1] - origin[1]
    return (dx * math.cos(r) - dy * math.sin(r) + origin[0], dx * math.sin(r) + dy * math.cos(r) + origin[1])


def _crossing(a: Point, b: Point, c: Point, d: Point) -> Point | None:
    """Where segments ab and cd cross (None when they do not)."""
    r, s = (b[0] - a[0], b[1] - a[1]), (d[0] - c[0], d[1] - c[1])
    den = r[0] * s[1] - r[1] * s[0]
    if abs(den) < 1e-12:
        return None
    t = ((c[0] - a[0]) * s[1] - (c[1] - a[1]) * s[0]) / den
    u = ((c[0] - a[0]) * r[1] - (c[1] - a[1]) * r[0]) / den
    if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
        return (a[0] + t * r[0], a[1] + t * r[1])
    return None


def _chord(line: tuple[Point, Point], polygon: list[Point]) -> tuple[Point, Point] | None:
    """The longest piece of ``line`` between two of its crossings with the polygon's edges (in edge order)."""
    hits: list[Point] = []
    for i in range(len(polygon)):
        hit = _crossing(*line, polygon[i], polygon[(i + 1) % len(polygon)])
        if hit is not None and hit not in hits:
            hits.append(hit)
    best, length = None, 0.0
    for p in hits:
        for q in hits:
            if math.dist(p, q) > length:
                best, length = (p, q), math.dist(p, q)
    return best


def _survey_lines(polygon: list[Point], angle: float, spacing: float) -> list[tuple[Point, Point]]:
    xs, ys = [p[0] for p in polygon], [p[1] for p in polygon]
    center = ((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2)
    half = (max(max(xs) - min(xs), max(ys) - min(ys)) + 2000.0) / 2.0
    angle = angle - 180.0 if angle > 90.0 else angle + 180.0 if angle < -90.0 else angle
    lines, x = [], center[0] - half
    while x < center[0] + half:
        line = (_rotate((x, center[1] - half), center, angle), _rotate((x, center[1] + half), center, angle))
        chord = _chord(line, polygon)
        if chord is not None:
            lines.append(chord)
        x += spacing
    if len(lines) < 2:  # a polygon thinner than the spacing: one line through its middle
        middle = (_rotate((center[0], center[1] - half), center, angle),
                  _rotate((center[0], center[1] + half), center, angle))
        chord = _chord(middle, polygon)
        lines = [chord] if chord is not None else lines
    if not lines:
        raise TransectError("no transect crosses its polygon")
    first = math.atan2(lines[0][1][1] - lines[0][0][1], lines[0][1][0] - lines[0][0][0])
    same = []
    for a, b in lines:  # every line the first one's way
        heading = math.atan2(b[1] - a[1], b[0] - a[0])
        same.append((a, b) if abs(math.remainder(heading - first, 2 * math.pi)) < math.pi / 2 else (b, a))
    return same


def _order(lines: list[tuple[Point, Point]], entry: int, alternate: bool) -> list[tuple[Point, Point]]:
    """The transects in flying order from the entry corner (0 top left, 1 top right, 2 bottom left,
    3 bottom right), every other one flown back."""
    if entry in (2, 3):
        lines = [(b, a) for a, b in lines]
    if entry in (1, 3):
        lines = lines[::-1]
    if alternate:
        lines = lines[0::2] + lines[1::2][::-1]
    return [(b, a) if i % 2 else (a, b) for i, (a, b) in enumerate(lines)]


def _extend(a: Point, b: Point, distance: float) -> tuple[Point, Point]:
    length = math.dist(a, b)
    if distance <= 0 or length < 1e-9:
        return a, b
    ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
    return (a[0] - ux * distance, a[1] - uy * distance), (b[0] + ux * distance, b[1] + uy * distance)


class _Items:
    """Waypoints and camera triggers of the transects, in the plan's frame and altitude."""

    def __init__(self, plane: _Plane, altitude: float, frame: int, trigger: float, turnaround: float) -> None:
        self.plane, self.altitude, self.frame = plane, altitude, frame
        self.trigger, self.turnaround = trigger, turnaround
        self.items: list[Item] = []

    def waypoint(self, point: Point, altitude: float | None = None) -> None:
        lat, lon = self.plane.to_geo(point)
        alt = self.altitude if altitude is None else altitude
        self.items.append((WAYPOINT, self.frame, (0.0, 0.0, 0.0, math.nan, lat, lon, alt)))

    def camera(self, distance: float) -> None:
        self.items.append((TRIGGER, 2, (distance, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0)))

    def transects(self, lines: list[list[Point]], in_turnaround: bool) -> list[Item]:
        if in_turnaround:
            self.camera(self.trigger)
        for points in lines:
            start, end = _extend(points[0], points[-1], self.turnaround)
            if self.turnaround > 0:
                self.waypoint(start)
            self.waypoint(points[0])
            if not in_turnaround:
                self.camera(self.trigger)
            for point in points[1:]:
                self.waypoint(point)
            if not in_turnaround:
                self.camera(0.0)
            if self.turnaround > 0:
                self.waypoint(end)
        if in_turnaround:
            self.camera(0.0)
        return self.items


def _scan(item: dict, key: str, minimum: int) -> tuple[_Items, list[Point], dict, dict]:
    """What every transect item starts from: its items' builder, its points on the plane, its camera and style."""
    places = _polygon(item, key, minimum)
    camera, altitude, frame = _camera(item)
    style = item.get("TransectStyleComplexItem", {})
    plane = _Plane(places[0])
    turnaround = max(number(style.get("TurnAroundDistance")), 0.0) if style.get("TurnAroundDistance") else 0.0
    builder = _Items(plane, altitude, frame, _spacing(camera, "AdjustedFootprintFrontal"), turnaround)
    return builder, [plane.to_plane(*p) for p in places], camera, style


def _survey(item: dict) -> list[Item]:
    builder, polygon, camera, style = _scan(item, "polygon", 3)
    angle = number(item.get("angle"))
    angle = 0.0 if math.isnan(angle) else angle
    spacing = _spacing(camera, "AdjustedFootprintSide")
    lines = _order(_survey_lines(polygon, angle, spacing), int(number(item.get("entryLocation")) or 0),
                   bool(item.get("flyAlternateTransects")))
    if style.get("Refly90Degrees"):
        lines += _order(_survey_lines(polygon, angle + 90.0, spacing), 0, False)
    return builder.transects([[a, b] for a, b in lines], bool(style.get("CameraTriggerInTurnAround", True)))


def _offset(points: list[Point], distance: float) -> list[Point]:
    """The polyline moved ``distance`` meters to its right (left when negative), corners on the bisectors."""
    normals = []
    for a, b in zip(points, points[1:], strict=False):
        length = math.dist(a, b) or 1.0
        normals.append(((b[1] - a[1]) / length, -(b[0] - a[0]) / length))
    moved = []
    for i, p in enumerate(points):
        n1, n2 = normals[max(i - 1, 0)], normals[min(i, len(normals) - 1)]
        nx, ny = n1[0] + n2[0], n1[1] + n2[1]
        scale = (nx * n1[0] + ny * n1[1]) or 1.0
        moved.append((p[0] + nx * distance / scale, p[1] + ny * distance / scale))
    return moved


def _corridor(item: dict) -> list[Item]:
    builder, points, camera, style = _scan(item, "polyline", 2)
    width = number(item.get("CorridorWidth"))
    if not width > 0:
        raise TransectError("it needs a CorridorWidth above 0", item)
    spacing = _spacing(camera, "AdjustedFootprintSide")
    count = max(1, math.ceil(width / spacing))
    lines = []
    for i in range(count):
        offset = 0.0 if count == 1 else width / 2.0 - spacing / 2.0 - i * spacing
        line = _offset(points, offset)
        lines.append(line[::-1] if i % 2 else line)
    return builder.transects(lines, bool(style.get("CameraTriggerInTurnAround", True)))


def _structure(item: dict) -> list[Item]:
    builder, polygon, _, _ = _scan(item, "polygon", 3)
    distance = builder.altitude  # the camera's distance to the structure's faces
    area = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(polygon, polygon[1:] + polygon[:1], strict=True))
    ring = _offset(polygon + polygon[:1], -distance if area > 0 else distance)[:-1]  # pushed out of the structure
    ring = ring + ring[:1]
    layers = max(int(number(item.get("Layers")) or 1), 1)
    bottom, height = number(item.get("ScanBottomAlt")), number(item.get("StructureHeight"))
    if math.isnan(height) or height <= 0:
        raise TransectError("it needs a StructureHeight above 0", item)
    bottom = 0.0 if math.isnan(bottom) else bottom
    step = max(height - bottom, 0.0) / layers
    altitudes = [bottom + step / 2.0 + i * step for i in range(layers)]
    if item.get("StartFromTop"):
        altitudes.reverse()
    entrance = number(item.get("EntranceAltitude"))
    entrance = altitudes[0] if math.isnan(entrance) else entrance
    builder.waypoint(ring[0], entrance)
    for altitude in altitudes:
        builder.waypoint(ring[0], altitude)
        builder.camera(builder.trigger)
        for point in ring[1:]:
            builder.waypoint(point, altitude)
        builder.camera(0.0)
    builder.waypoint(ring[0], entrance)
    return builder.items


def scan_items(kind: str, item: dict, home: Geodetic | None = None) -> list[Item]:
    """The items of a complex item of ``kind`` (survey, CorridorScan, StructureScan) computed from ``item``."""
    return {"survey": _survey, "CorridorScan": _corridor, "StructureScan": _structure}[kind](item)
