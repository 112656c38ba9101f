"""A tree that is a sequence of items written back as mission items: a QGroundControl ``.plan`` or a QGC WPL 110
``.waypoints`` file, so a mission verified here loads into QGroundControl or Mission Planner.

The behaviors the item reader makes (:mod:`aeroexec.trees.items.behaviors`) become the items they came from:
TAKE_OFF NAV_TAKEOFF; GO_TO_POINT NAV_WAYPOINT (with the WAIT after it as its hold time, DO_CHANGE_SPEED and
DO_SET_ROI_LOCATION / DO_SET_ROI_NONE before it as its SPEED and point to look at change); LAND NAV_LAND;
WAIT NAV_DELAY; TAKE_PHOTO IMAGE_START_CAPTURE of one photo; LOOK_AT_A_POINT DO_SET_ROI_LOCATION; ROTATE
CONDITION_YAW; DROP_ITEM DO_GRIPPER; KEEP_HOVERING NAV_LOITER_UNLIM; a Parallel of TRIGGER_CAMERA or RECORD_VIDEO
beside items their start and stop items; a Parallel of KEEP_LOITERING and WAIT NAV_LOITER_TURNS; a Repeat DO_JUMP.
Positions are relative-altitude global items (MAV_FRAME_GLOBAL_RELATIVE_ALT); local meters are placed from the
mission's home. Anything else (a Fallback, a condition, a behavior no item flies) has no item: it is refused at its
line.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from aeroexec.drones.geodesy import Geodetic, enu_to_geodetic, geo_to_enu, is_geo, parse_geo
from aeroexec.trees.items.behaviors import LOITER_SPEED, PlanDocument
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.ports import parse_value

RELATIVE, MISSION = 3, 2
NAN = math.nan


class WriteError(ValueError):
    """A tree with a node no mission item flies; ``problems`` are ``(file, line, message)``."""

    def __init__(self, problems: list[tuple[str, int, str]]) -> None:
        super().__init__("\n".join(f"{f}:{line}: {m}" for f, line, m in problems))
        self.problems = problems


@dataclass
class Written:
    """One item to write: MAV_CMD, MAV_FRAME and its seven parameters (latitude, longitude, altitude last)."""

    command: int
    frame: int
    params: list[float]


class _Writer:
    def __init__(self, document: TreeDocument, home: Geodetic) -> None:
        self.document, self.home = document, home
        self.items: list[Written] = []
        self.position = (0.0, 0.0, 0.0)
        self.speed: str | None = None
        self.roi: str | None = None
        self.problems: list[tuple[str, int, str]] = []

    def refuse(self, node: TreeNode, why: str) -> None:
        self.problems.append((node.file or self.document.file, node.line, f"{node.type} {why}: only a sequence of "
                                                                         f"mission items converts to a plan"))

    def add(self, command: int, frame: int = MISSION, *params: float) -> Written:
        item = Written(command, frame, [*params, *([0.0] * (7 - len(params)))])
        self.items.append(item)
        return item

    def place(self, node: TreeNode, key: str) -> tuple[float, float, float] | None:
        """A point port as (latitude, longitude, altitude above home); ENU meters are placed from home."""
        text = node.ports.get(key, "")
        if is_geo(text):
            lat, lon, alt = parse_geo(text)
            self.position = geo_to_enu((lat, lon, alt), self.home)
            return lat, lon, alt
        value = parse_value(text)
        if not (isinstance(value, tuple) and len(value) == 3 and all(isinstance(v, int | float) for v in value)):
            self.refuse(node, f"with {key}={text!r} (not a literal point)")
            return None
        if key == "RELATIVE_COORDINATES":
            value = tuple(p + d for p, d in zip(self.position, value, strict=True))
        self.position = tuple(float(v) for v in value)
        lat, lon, _ = enu_to_geodetic((self.position[0], self.position[1], 0.0), self.home)
        return lat, lon, self.position[2]

    def here(self) -> tuple[float, float, float]:
        lat, lon, _ = enu_to_geodetic((self.position[0], self.position[1], 0.0), self.home)
        return lat, lon, self.position[2]

    def number(self, node: TreeNode, key: str, default: float) -> float:
        value = parse_value(node.ports[key]) if key in node.ports else default
        if not isinstance(value, int | float):
            self.refuse(node, f"with {key}={node.ports.get(key)!r} (not a literal number)")
            return default
        return float(value)

    # -- nodes ---------------------------------------------------------------------------------------------------
    def node(self, node: TreeNode) -> None:
        handler = getattr(self, f"_{node.type.lower()}", None)
        if handler is None:
            self.refuse(node, "has no mission item")
        else:
            handler(node)

    def _sequence(self, node: TreeNode) -> None:
        for child in node.children:
            self.node(child)

    def _repeat(self, node: TreeNode) -> None:
        first = len(self.items) + 1
        cycles = int(self.number(node, "num_cycles", 1))
        self._sequence(node)
        if cycles > 1:
            self.add(177, MISSION, first, cycles - 1)
        elif cycles < 0:
            self.refuse(node, "without end")

    def _parallel(self, node: TreeNode) -> None:
        kinds = [c.type for c in node.children]
        if kinds == ["KEEP_LOITERING", "WAIT"]:
            loiter, wait = node.children
            radius = self.number(loiter, "RADIUS", 2.0)
            speed = min(LOITER_SPEED, max(0.5, 0.5 * radius))
            turns = self.number(wait, "DURATION", 0.0) * speed / (2.0 * math.pi * radius)
            clockwise = loiter.ports.get("CLOCKWISE", "true").lower() != "false"
            lat, lon, alt = self.here()
            self.add(18, RELATIVE, round(turns, 3), 0.0, radius if clockwise else -radius, 0.0, lat, lon, alt)
            return
        if len(node.children) != 2 or kinds[1] not in ("TRIGGER_CAMERA", "RECORD_VIDEO"):
            self.refuse(node, "beside anything but a camera trigger or a video")
            return
        body, beside = node.children
        if beside.type == "RECORD_VIDEO":
            self.add(2500)
            self.node(body)
            self.add(2501)
        elif "DISTANCE" in beside.ports:
            self.add(206, MISSION, self.number(beside, "DISTANCE", 0.0), 0.0, 0.0)
            self.node(body)
            self.add(206, MISSION, 0.0, 0.0, 0.0)
        else:
            count = self.number(beside, "COUNT", 0.0)
            self.add(2000, MISSION, 0.0, self.number(beside, "INTERVAL", 1.0), count)
            self.node(body)
            self.add(2001)

    def _take_off(self, node: TreeNode) -> None:
        altitude = self.number(node, "ALTITUDE", 2.0)
        self.position = (self.position[0], self.position[1], altitude)
        lat, lon, _ = self.here()
        self.add(22, RELATIVE, 0.0, 0.0, 0.0, NAN, lat, lon, altitude)

    def _go_to_point(self, node: TreeNode) -> None:
        speed = node.ports.get("SPEED")
        if speed != self.speed:
            self.add(178, MISSION, 1.0, self.number(node, "SPEED", -2.0) if speed else -2.0, -1.0)
            self.speed = speed
        look = node.ports.get("POINT_TO_LOOK_DURING_FLIGHT")
        if look != self.roi:
            if look is None:
                self.add(197)
            else:
                saved = self.position
                where = self.place(node, "POINT_TO_LOOK_DURING_FLIGHT")
                self.position = saved
                if where is not None:
                    self.add(195, RELATIVE, 0.0, 0.0, 0.0, 0.0, *where)
            self.roi = look
        where = self.place(node, "COORDINATES" if "COORDINATES" in node.ports else "RELATIVE_COORDINATES")
        if where is None:
            return
        yaw = node.ports.get("YAW_ANGLE_AT_THE_END")
        heading = NAN if yaw is None else (90.0 - self.number(node, "YAW_ANGLE_AT_THE_END", 0.0)) % 360.0
        accept = self.number(node, "ACCEPTANCE_RADIUS", 0.0)
        self.add(16, RELATIVE, 0.0, accept, 0.0, heading, *where)

    def _wait(self, node: TreeNode) -> None:
        seconds = self.number(node, "DURATION", 0.0)
        if "DURATION" not in node.ports:
            self.refuse(node, "for a marker")
        elif self.items and self.items[-1].command == 16 and self.items[-1].params[0] == 0:
            self.items[-1].params[0] = seconds  # a waypoint's hold time
        else:
            self.add(93, MISSION, seconds, -1.0, -1.0, -1.0)

    def _land(self, node: TreeNode) -> None:
        lat, lon, _ = self.here()
        self.add(21, RELATIVE, 0.0, 0.0, 0.0, NAN, lat, lon, 0.0)
        self.position = (self.position[0], self.position[1], 0.0)

    def _take_photo(self, node: TreeNode) -> None:
        self.add(2000, MISSION, 0.0, 0.0, 1.0)

    def _look_at_a_point(self, node: TreeNode) -> None:
        saved = self.position
        where = self.place(node, "COORDINATES")
        self.position = saved
        if where is not None:
            self.add(195, RELATIVE, 0.0, 0.0, 0.0, 0.0, *where)
            self.roi = node.ports["COORDINATES"]

    def _rotate(self, node: TreeNode) -> None:
        if "ANGLE" in node.ports:
            self.add(115, MISSION, (90.0 - self.number(node, "ANGLE", 0.0)) % 360.0, 0.0, 0.0, 0.0)
        else:
            turn = self.number(node, "RELATIVE_ANGLE", 0.0)  # ours counterclockwise, MAVLink's clockwise
            self.add(115, MISSION, abs(turn), 0.0, 1.0 if turn < 0 else -1.0, 1.0)

    def _drop_item(self, node: TreeNode) -> None:
        self.add(211, MISSION, 0.0, 0.0)

    def _keep_hovering(self, node: TreeNode) -> None:
        self.add(17, RELATIVE, 0.0, 0.0, 0.0, NAN, *self.here())


def mission_items(document: TreeDocument, home: Geodetic) -> list[Written]:
    """The items of ``document`` placed from ``home``; raises :class:`WriteError` for nodes no item flies."""
    writer = _Writer(document, home)
    writer.node(document.root)
    if writer.problems:
        raise WriteError(writer.problems)
    return writer.items


def _json_number(value: float) -> Any:
    return None if math.isnan(value) else (int(value) if float(value).is_integer() and abs(value) < 1e15
                                           else round(value, 8))


def write_plan(document: TreeDocument, home: Geodetic) -> str:
    """The mission as a QGroundControl ``.plan`` (JSON), with its geofence and rally points when it had them."""
    items = mission_items(document, home)
    mission = document.mission if isinstance(document, PlanDocument) else None
    polygons, circles, rally = [], [], []
    for fence in mission.fences if mission is not None else ():
        if fence.center is not None:
            circles.append({"circle": {"center": list(fence.center), "radius": fence.radius},
                            "inclusion": fence.inclusion, "version": 1})
        else:
            polygons.append({"inclusion": fence.inclusion, "polygon": [list(v) for v in fence.vertices],
                             "version": 1})
    for (lat, lon, alt), _ in mission.rally if mission is not None else ():
        rally.append([lat, lon, alt])
    plan = {"fileType": "Plan", "geoFence": {"circles": circles, "polygons": polygons, "version": 2},
            "groundStation": "aeroexec",
            "mission": {"cruiseSpeed": 15, "firmwareType": 12, "globalPlanAltitudeMode": 1, "hoverSpeed": 5,
                        "items": [{"autoContinue": True, "command": item.command, "doJumpId": seq,
                                   "frame": item.frame, "params": [_json_number(p) for p in item.params],
                                   "type": "SimpleItem"} for seq, item in enumerate(items, start=1)],
                        "plannedHomePosition": [home[0], home[1], home[2]], "vehicleType": 2, "version": 2},
            "rallyPoints": {"points": rally, "version": 2}, "version": 1}
    return json.dumps(plan, indent=4) + "\n"


def write_waypoints(document: TreeDocument, home: Geodetic) -> str:
    """The mission as a QGC WPL 110 file (Mission Planner's ``.waypoints``): home on line 0, then the items."""
    items = mission_items(document, home)

    def field(value: float, digits: int) -> str:
        return f"{0.0 if math.isnan(value) else value:.{digits}f}"

    lines = ["QGC WPL 110", "\t".join(["0", "1", "0", "16", "0", "0", "0", "0", field(home[0], 8), field(home[1], 8),
                                       field(home[2], 6), "1"])]
    for seq, item in enumerate(items, start=1):
        p = list(item.params)
        if item.command == 16 and p[3] == 0.0:
            p[3] = 360.0  # north: a waypoint file's 0 means "no yaw", as ArduPilot reads it
        lines.append("\t".join([str(seq), "0", str(item.frame), str(item.command),
                                *(field(v, 8) for v in p[:4]), field(p[4], 8), field(p[5], 8), field(p[6], 6), "1"]))
    return "\n".join(lines) + "\n"


__all__ = ["WriteError", "mission_items", "write_plan", "write_waypoints"]
