"""QGroundControl missions (``.plan``, QGroundControl's documented JSON) as behavior trees of the catalog's behaviors.

The mission's items, numbered as QGroundControl uploads them (0 is home; a survey's generated items each have their
own number), become one ``Sequence`` of behaviors, positions converted from latitude/longitude to ENU meters from
the world's home point (``drones.geodesy``):

| MAV_CMD | behaviors |
|---|---|
| NAV_TAKEOFF 22 | TAKE_OFF (to the item's altitude), then GO_TO_POINT when it names a place away from home |
| NAV_WAYPOINT 16 | GO_TO_POINT (yaw at the end, SPEED and the region of interest as set), then WAIT for its hold time |
| NAV_LOITER_TIME 19 | GO_TO_POINT, then WAIT its time |
| NAV_LAND 21 | GO_TO_POINT above its place (when it has one), LAND |
| NAV_RETURN_TO_LAUNCH 20 | GO_TO_POINT above the nearest of home and the rally points, LAND |
| DO_CHANGE_SPEED 178 | the SPEED of the GO_TO_POINTs after it |
| IMAGE_START_CAPTURE 2000 | TAKE_PHOTO (one image), or one at every waypoint until IMAGE_STOP_CAPTURE 2001 |
| DO_DIGICAM_CONTROL 203 | TAKE_PHOTO (shot 1) |
| DO_SET_CAM_TRIGG_DIST 206 | TAKE_PHOTO at every waypoint while the distance is not 0 (surveys) |
| DO_SET_ROI_LOCATION 195, DO_SET_ROI 201 | LOOK_AT_A_POINT; the GO_TO_POINTs after it look at it until ROI none |

Complex items ``survey`` and ``CorridorScan`` fly their ``TransectStyleComplexItem.Items`` (the items QGroundControl
generated), or their ``VisualTransectPoints`` at the camera's distance to the surface. The geofence (inclusion
and exclusion polygons and circles) and the rally points are kept on the document. Every item that cannot be
mapped, every waypoint that breaks the geofence, is a problem with its item number and line; none is dropped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.drones.geodesy import Geodetic, geodetic_to_enu
from aeroexec.engine.errors import WRONG_FORMAT, WRONG_VALUE
from aeroexec.engine.missions.check import MissionProblem
from aeroexec.trees.loaders.geofence import Fence, breach
from aeroexec.trees.loaders.lined_json import Lined, parse_json
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode

from aeroexec.limits import InputError, read_text

Vector = tuple[float, float, float]
COMMANDS = {16: "NAV_WAYPOINT", 17: "NAV_LOITER_UNLIM", 18: "NAV_LOITER_TURNS", 19: "NAV_LOITER_TIME",
            20: "NAV_RETURN_TO_LAUNCH", 21: "NAV_LAND", 22: "NAV_TAKEOFF", 93: "NAV_DELAY", 177: "DO_JUMP",
            178: "DO_CHANGE_SPEED", 183: "DO_SET_SERVO", 195: "DO_SET_ROI_LOCATION", 197: "DO_SET_ROI_NONE",
            201: "DO_SET_ROI", 203: "DO_DIGICAM_CONTROL", 206: "DO_SET_CAM_TRIGG_DIST", 2000: "IMAGE_START_CAPTURE",
            2001: "IMAGE_STOP_CAPTURE"}
RELATIVE_FRAMES = (3, 6, 10)  # GLOBAL_RELATIVE_ALT(_INT), GLOBAL_TERRAIN_ALT (the simulated ground is flat)
ABSOLUTE_FRAMES = (0, 5)  # GLOBAL(_INT): altitude above mean sea level
TRANSECT_ITEMS = ("survey", "CorridorScan")


@dataclass
class PlanDocument(TreeDocument):
    """A converted plan: the tree to fly, and what the plan says besides (ENU meters from the world's home)."""

    fences: list[Fence] = field(default_factory=list)
    rally_points: list[Vector] = field(default_factory=list)
    problems: list[MissionProblem] = field(default_factory=list)


def _number(value: Any) -> float:
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else math.nan


def _text(*values: float) -> str:
    def one(value: float) -> str:
        text = f"{value:.2f}".rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text

    return ", ".join(one(v) for v in values)


class _Converter:
    """The mission items, in order, into the children of the main Sequence (one state: where the drone will be)."""

    def __init__(self, file: str, home: Geodetic, document: PlanDocument) -> None:
        self.file, self.home, self.document = file, home, document
        self.nodes: list[TreeNode] = []
        self.position: Vector | None = None  # None: on the ground
        self.xy: tuple[float, float] = (0.0, 0.0)
        self.speed: float | None = None
        self.default_speed: float | None = None  # the plan's hoverSpeed
        self.roi: Vector | None = None
        self.photo_each_waypoint = False

    # -- reporting ------------------------------------------------------------------------------
    def problem(self, seq: int, line: int, message: str, severity: str = "error", kind: str = WRONG_FORMAT) -> None:
        self.document.problems.append(MissionProblem(severity, f"item {seq}: {message}", self.file, line, kind))

    def node(self, kind: str, seq: int, label: str, line: int, **ports: str) -> TreeNode:
        node = TreeNode(kind, f"item {seq} {label}", dict(ports), [], self.file, line)
        self.nodes.append(node)
        return node

    # -- positions --------------------------------------------------------------------------------
    def enu(self, lat: float, lon: float, alt: float, frame: int) -> Vector:
        east, north, _ = geodetic_to_enu((lat, lon, self.home[2]), self.home)
        up = alt - self.home[2] if frame in ABSOLUTE_FRAMES else alt
        return (east, north, up)

    def place(self, item: dict, seq: int, name: str) -> Vector | None | bool:
        """The item's position (None: it names none, False: a frame that cannot be converted)."""
        params = item["params"]
        lat, lon, alt = (_number(v) for v in params[4:7])
        frame = item.get("frame", 3)
        if math.isnan(lat) or math.isnan(lon) or (lat == 0 and lon == 0):
            return None
        if frame not in RELATIVE_FRAMES + ABSOLUTE_FRAMES:
            self.problem(seq, item.line, f"{name} in MAV_FRAME {frame}: only global frames (0, 3, 5, 6, 10) "
                                         "can be placed in the world")
            return False
        if math.isnan(alt):
            alt = self.position[2] if self.position else 0.0
            frame = 3
        return self.enu(lat, lon, alt, frame)

    def required_place(self, item: dict, seq: int, name: str) -> Vector | None:
        """The position of an item that needs one (None, the problem reported, when it has none)."""
        where = self.place(item, seq, name)
        if where is None:
            self.problem(seq, item.line, f"{name} without a latitude and longitude")
        return where or None

    def check_fence(self, seq: int, line: int, name: str, point: Vector) -> None:
        why = breach(self.document.fences, point[:2])
        if why:
            self.problem(seq, line, f"{name} at ({_text(*point)}) is {why}", kind=WRONG_VALUE)

    def go_to(self, seq: int, line: int, name: str, point: Vector, yaw: float = math.nan) -> None:
        ports = {"COORDINATES": _text(*point)}
        if self.speed is not None:
            ports["SPEED"] = _text(self.speed)
        if self.roi is not None:
            ports["POINT_TO_LOOK_DURING_FLIGHT"] = _text(*self.roi)
        elif not math.isnan(yaw):
            ours = (90.0 - yaw + 180.0) % 360.0 - 180.0  # MAVLink: 0 north, clockwise; ours: 0 east, counter-
            ports["YAW_ANGLE_AT_THE_END"] = _text(ours)
        self.node("GO_TO_POINT", seq, name, line, **ports)
        self.check_fence(seq, line, name, point)
        self.position, self.xy = point, point[:2]
        if self.photo_each_waypoint:
            self.node("TAKE_PHOTO", seq, "photo", line)

    # -- one item -----------------------------------------------------------------------------------
    def simple(self, item: dict, seq: int) -> None:
        command = item.get("command")
        params = item.get("params")
        if not isinstance(command, int) or not isinstance(params, list) or len(params) != 7:
            self.problem(seq, item.line, "a SimpleItem needs a MAV_CMD \"command\" and 7 \"params\"")
            return
        name = COMMANDS.get(command, f"MAV_CMD {command}")
        handler = getattr(self, "_" + name.lower().removeprefix("do_"), None)
        if handler is None:
            self.problem(seq, item.line, f"MAV_CMD {command}" + (f" ({name})" if command in COMMANDS else "") +
                         " has no behavior in aeroexec: the plan cannot fly as written")
            return
        handler(item, seq, name.removeprefix("NAV_").removeprefix("DO_"), [_number(v) for v in params])

    def _nav_takeoff(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        where = self.place(item, seq, name)
        if where is False:
            return
        altitude = params[6] - (self.home[2] if item.get("frame", 3) in ABSOLUTE_FRAMES else 0.0)
        if math.isnan(altitude):
            self.problem(seq, item.line, f"{name} without an altitude (params[6])")
            return
        if self.position is not None:
            self.problem(seq, item.line, "a take-off while flying", kind="WRONG_SEQUENCE")
        self.node("TAKE_OFF", seq, name, item.line, ALTITUDE=_text(altitude))
        self.check_fence(seq, item.line, name, (*self.xy, altitude))
        self.position = (*self.xy, altitude)
        if where is not None and math.dist(where[:2], self.xy) > 1.0:
            self.go_to(seq, item.line, name, (where[0], where[1], altitude))

    def _nav_waypoint(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        where = self.required_place(item, seq, name)
        if where is None:
            return
        if self.position is None:
            self.problem(seq, item.line, f"the plan flies to {name} before any NAV_TAKEOFF: aeroexec takes off "
                                         f"to its altitude ({_text(where[2])} m) first", severity="warning")
            self.node("TAKE_OFF", seq, "take-off", item.line, ALTITUDE=_text(where[2]))
        self.go_to(seq, item.line, name, where, params[3])
        if params[0] > 0:
            self.node("WAIT", seq, "hold", item.line, DURATION=_text(params[0]))

    def _nav_loiter_time(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        where = self.place(item, seq, name)
        if where is False:
            return
        if where is not None:
            self.go_to(seq, item.line, name, where)
        self.node("WAIT", seq, name if where is None else "loiter", item.line, DURATION=_text(max(params[0], 0)))

    def _nav_land(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        where = self.place(item, seq, name)
        if where is False:
            return
        if where is not None and self.position is not None and math.dist(where[:2], self.xy) > 0.5:
            self.go_to(seq, item.line, name, (where[0], where[1], self.position[2]))
        self.node("LAND", seq, name, item.line)
        self.position = None

    def _nav_return_to_launch(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        places = [(0.0, 0.0), *[p[:2] for p in self.document.rally_points]]
        target = min(places, key=lambda p: math.dist(p, self.xy))
        altitude = max(self.position[2] if self.position else 0.0, 2.0)
        if math.dist(target, self.xy) > 0.5:
            self.go_to(seq, item.line, name, (*target, altitude))
        self.node("LAND", seq, "land", item.line)
        self.position = None

    def _change_speed(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        if params[1] == -2:
            self.speed = self.default_speed
        elif params[1] > 0:
            self.speed = params[1]
        elif params[1] != -1:
            self.problem(seq, item.line, f"{name} to {_text(params[1])} m/s", kind=WRONG_VALUE)

    def _image_start_capture(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        if params[2] == 1 or not params[1] > 0:
            self.node("TAKE_PHOTO", seq, name, item.line)
        else:
            self.photo_each_waypoint = True

    def _image_stop_capture(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        self.photo_each_waypoint = False

    def _digicam_control(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        if params[4] == 1:
            self.node("TAKE_PHOTO", seq, name, item.line)

    def _set_cam_trigg_dist(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        self.photo_each_waypoint = params[0] > 0
        if params[2] == 1:
            self.node("TAKE_PHOTO", seq, name, item.line)

    def _set_roi_location(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        where = self.required_place(item, seq, name)
        if where is None:
            return
        self.roi = where
        if self.position is not None:
            self.node("LOOK_AT_A_POINT", seq, name, item.line, COORDINATES=_text(*where))

    def _set_roi(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        if params[0] == 0:
            self.roi = None
        elif params[0] == 3:
            self._set_roi_location(item, seq, name, params)
        else:
            self.problem(seq, item.line, f"{name} in MAV_ROI mode {params[0]:g}: only a location (3) or none (0) "
                                         "has a behavior")

    def _set_roi_none(self, item: dict, seq: int, name: str, params: list[float]) -> None:
        self.roi = None

    def transect(self, item: dict, seq: int) -> int:
        """A survey or corridor scan: its generated items (how many item numbers it takes is returned)."""
        style = item.get("TransectStyleComplexItem")
        if not isinstance(style, dict):
            self.problem(seq, item.line, f"a {item.get('complexItemType')} needs its TransectStyleComplexItem")
            return 1
        generated = style.get("Items")
        if isinstance(generated, list) and generated:
            for offset, inner in enumerate(generated):
                if isinstance(inner, dict) and inner.get("type") == "SimpleItem":
                    self.simple(inner, seq + offset)
                else:
                    self.problem(seq + offset, getattr(inner, "line", item.line), "a survey's Items are SimpleItems")
            return len(generated)
        points = style.get("VisualTransectPoints") or []
        camera = style.get("CameraCalc") if isinstance(style.get("CameraCalc"), dict) else {}
        altitude = _number(camera.get("DistanceToSurface"))
        if not points or math.isnan(altitude):
            self.problem(seq, item.line, "a survey without Items needs VisualTransectPoints and "
                                         "CameraCalc.DistanceToSurface")
            return 1
        photos, self.photo_each_waypoint = self.photo_each_waypoint, True
        for offset, point in enumerate(points):
            if not (isinstance(point, list) and len(point) >= 2):
                self.problem(seq + offset, item.line, "a transect point is [latitude, longitude]")
                continue
            self.go_to(seq + offset, item.line, "transect", self.enu(_number(point[0]), _number(point[1]),
                                                                      altitude, 3))
        self.photo_each_waypoint = photos
        return len(points)


def _fences(plan: dict, file: str, home: Geodetic, problems: list[tuple[str, int, str]]) -> list[Fence]:
    fence = plan.get("geoFence")
    if not isinstance(fence, dict):
        return []

    def xy(point: Any, line: int) -> tuple[float, float] | None:
        if isinstance(point, list) and len(point) >= 2 and all(isinstance(v, int | float) for v in point[:2]):
            east, north, _ = geodetic_to_enu((float(point[0]), float(point[1]), home[2]), home)
            return (east, north)
        problems.append((file, line, f"a geofence point is [latitude, longitude], not {point!r}"))
        return None

    found: list[Fence] = []
    polygons = list(fence.get("polygons") or [])
    if isinstance(fence.get("polygon"), list):  # version 1: one inclusion polygon
        polygons.append(Lined(polygon=fence["polygon"], inclusion=True))
        polygons[-1].line = fence.line
    for polygon in polygons:
        line = getattr(polygon, "line", fence.line)
        vertices = [xy(p, line) for p in polygon.get("polygon") or []] if isinstance(polygon, dict) else []
        if len(vertices) < 3 or None in vertices:
            problems.append((file, line, "a geofence polygon needs 3 or more [latitude, longitude] points"))
            continue
        found.append(Fence(bool(polygon.get("inclusion", True)), tuple(vertices), line=line))  # type: ignore[arg-type]
    for circle in fence.get("circles") or []:
        line = getattr(circle, "line", fence.line)
        shape = circle.get("circle") if isinstance(circle, dict) else None
        center = xy(shape.get("center"), line) if isinstance(shape, dict) else None
        radius = _number(shape.get("radius")) if isinstance(shape, dict) else math.nan
        if center is None or not radius > 0:
            problems.append((file, line, "a geofence circle needs a center [latitude, longitude] and a radius > 0"))
            continue
        found.append(Fence(bool(circle.get("inclusion", True)), center=center, radius=radius, line=line))
    return found


def read_plan(text: str, file: str, home: Geodetic | None = None) -> PlanDocument:
    """The plan in ``text`` as a tree, converted from ``home`` (default: the default simulated world's home)."""
    if home is None:
        from aeroexec.drones.sim import default_world

        home = default_world().home
    plan = parse_json(text, file)
    errors: list[tuple[str, int, str]] = []
    if not isinstance(plan, dict) or plan.get("fileType") != "Plan":
        raise TreeFormatError([(file, getattr(plan, "line", 1), "not a QGroundControl plan: \"fileType\" must be "
                                                                 "\"Plan\"")])
    mission = plan.get("mission")
    items = mission.get("items") if isinstance(mission, dict) else None
    if not isinstance(items, list) or not items:
        raise TreeFormatError([(file, getattr(mission, "line", plan.line), "a plan's \"mission\" needs a list of "
                                                                           "\"items\" (at least one)")])
    fences = _fences(plan, file, home, errors)
    rally = plan.get("rallyPoints")
    points = rally.get("points", []) if isinstance(rally, dict) else []
    rally_points: list[Vector] = []
    for point in points:
        if isinstance(point, list) and len(point) == 3 and all(isinstance(v, int | float) for v in point):
            east, north, _ = geodetic_to_enu((float(point[0]), float(point[1]), home[2]), home)
            rally_points.append((east, north, float(point[2])))
        else:
            errors.append((file, rally.line, f"a rally point is [latitude, longitude, altitude], not {point!r}"))
    if errors:
        raise TreeFormatError(errors)
    main = Path(file).stem or "plan"
    document = PlanDocument({}, main, file, {main: mission.line}, fences=fences, rally_points=rally_points)
    converter = _Converter(file, home, document)
    speed = _number(mission.get("hoverSpeed"))
    converter.speed = converter.default_speed = speed if speed > 0 else None
    planned = mission.get("plannedHomePosition")
    if isinstance(planned, list) and len(planned) >= 2 and all(isinstance(v, int | float) for v in planned[:2]):
        east, north, _ = geodetic_to_enu((float(planned[0]), float(planned[1]), home[2]), home)
        if math.hypot(east, north) > 5.0:
            document.problems.append(MissionProblem(
                "warning", f"the plan's home is {math.hypot(east, north):.0f} m from the world's home "
                           f"({home[0]:.6f}, {home[1]:.6f}): positions are taken from the world's home", file,
                mission.line, WRONG_VALUE))
    seq = 1
    for item in items:
        kind = item.get("type") if isinstance(item, dict) else None
        line = getattr(item, "line", mission.line)
        if kind == "SimpleItem":
            converter.simple(item, seq)
            seq += 1
        elif kind == "ComplexItem" and item.get("complexItemType") in TRANSECT_ITEMS:
            seq += converter.transect(item, seq)
        else:
            what = item.get("complexItemType", kind) if isinstance(item, dict) else type(item).__name__
            converter.problem(seq, line, f"a {what} item has no behavior in aeroexec: the plan cannot fly as written")
            seq += 1
    for point in rally_points:
        why = breach(fences, point[:2])
        if why:
            document.problems.append(MissionProblem("warning", f"the rally point ({_text(*point)}) is {why}", file,
                                                    rally.line, WRONG_VALUE))
    document.trees[main] = TreeNode("Sequence", main, {}, converter.nodes, file, mission.line)
    return document


def load_plan(path: str | Path, home: Geodetic | None = None) -> PlanDocument:
    """The QGroundControl plan in ``path``."""
    try:
        text = read_text(path, what="the plan")  # size bound, UTF-8 with a line, never a FIFO or a device
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return read_plan(text, str(path), home)
