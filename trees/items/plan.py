"""QGroundControl's JSON missions into the item model: ``.plan`` (``fileType: Plan``) and the legacy ``.mission``.

Both item forms are read: ``params`` of 7 (QGroundControl 3.2 and later) and ``coordinate`` with ``params`` of 4
(older plans and ``.mission`` files, e.g. QGroundControl's own SectionTest.plan). Complex items fly the items
QGroundControl generated for them (``TransectStyleComplexItem.Items``); without those, a ``survey``,
``CorridorScan`` or ``StructureScan`` is computed from its own polygon, spacing and angle
(:mod:`aeroexec.trees.items.transects`). An empty geofence (``"polygon": []``, QGroundControl's "no fence") is no
fence. Every problem names its item number and line.
"""

from __future__ import annotations

import math
from typing import Any

from aeroexec.drones.geodesy import valid_latitude_longitude
from aeroexec.engine.errors import WRONG_VALUE
from aeroexec.trees.items.model import (
    MULTICOPTERS,
    VEHICLE_TYPES,
    GeoFence,
    ItemMission,
    MissionItem,
    number,
)
from aeroexec.trees.items.transects import TransectError, scan_items
from aeroexec.trees.loaders.lined_json import parse_json
from aeroexec.trees.model import TreeFormatError

ARDUPILOT = 3  # MAV_AUTOPILOT_ARDUPILOTMEGA, a plan's firmwareType
#: The complex items QGroundControl writes, the versions it reads, and what they are.
COMPLEX = {"survey": (3, 5, "survey"), "CorridorScan": (2, 3, "corridor scan"),
           "StructureScan": (2, 3, "structure scan")}
NOT_MULTICOPTER = {"fwLanding": "a fixed-wing landing pattern", "vtolLanding": "a VTOL landing pattern"}


def _line(value: Any, default: int) -> int:
    return getattr(value, "line", 0) or default


def _numbers(values: Any, count: int) -> tuple[float, ...] | None:
    if not isinstance(values, list) or len(values) != count:
        return None
    if any(v is not None and (isinstance(v, bool) or not isinstance(v, int | float)) for v in values):
        return None
    return tuple(number(v) for v in values)


class _PlanReader:
    """One JSON mission file into an :class:`ItemMission`; ``seq`` counts the items as they are uploaded."""

    def __init__(self, mission: ItemMission) -> None:
        self.mission = mission
        self.seq = 1

    def simple(self, item: dict, line: int, origin: str = "") -> None:
        seq, self.seq = self.seq, self.seq + 1
        command, frame = item.get("command"), item.get("frame", 2)
        if isinstance(command, bool) or not isinstance(command, int) or isinstance(frame, bool) or \
                not isinstance(frame, int):
            self.mission.problem(line, f"item {seq}: a SimpleItem needs an integer MAV_CMD \"command\" and "
                                       f"MAV_FRAME \"frame\"")
            return
        params = _numbers(item.get("params"), 7)
        if params is None:  # the older form: four params and a coordinate
            four, where = _numbers(item.get("params"), 4), _numbers(item.get("coordinate"), 3)
            if four is None or where is None:
                self.mission.problem(line, f"item {seq}: a SimpleItem needs 7 numeric \"params\", or 4 \"params\" "
                                           f"and a \"coordinate\" [latitude, longitude, altitude]")
                return
            params = four + where
        jump_id = item.get("doJumpId")
        self.mission.items.append(MissionItem(
            seq, command, frame, params, line, bool(item.get("autoContinue", True)),
            jump_id if isinstance(jump_id, int) and not isinstance(jump_id, bool) else None, origin))

    def complex(self, item: dict, line: int) -> None:
        kind = item.get("complexItemType")
        seq = self.seq
        if kind in NOT_MULTICOPTER:
            self.mission.problem(line, f"item {seq}: {NOT_MULTICOPTER[kind]} ({kind}) is not flown by a multicopter")
            self.seq += 1
            return
        if kind not in COMPLEX:
            self.mission.problem(line, f"item {seq}: a complex item of type {kind!r} has no behavior in aeroexec "
                                       f"(survey, CorridorScan and StructureScan have)")
            self.seq += 1
            return
        low, high, what = COMPLEX[kind]
        version = item.get("version")
        if not isinstance(version, int) or not low <= version <= high:
            self.mission.problem(line, f"item {seq}: a {what} of version {version!r}: QGroundControl writes "
                                       f"versions {low} to {high}; open the plan in QGroundControl and save it again")
            self.seq += 1
            return
        style = item.get("TransectStyleComplexItem")
        generated = style.get("Items") if isinstance(style, dict) else None
        origin = f"{what} item {seq}"
        if isinstance(generated, list) and generated:
            for inner in generated:
                if isinstance(inner, dict) and inner.get("type") == "SimpleItem":
                    self.simple(inner, _line(inner, line), origin)
                else:
                    self.mission.problem(_line(inner, line), f"item {self.seq}: a {what}'s Items are SimpleItems")
                    self.seq += 1
            return
        try:
            computed = scan_items(kind, item, self.mission.home)
        except TransectError as error:
            self.mission.problem(_line(error.node, line), f"item {seq}: {what}: {error}")
            self.seq += 1
            return
        self.mission.problem(line, f"item {seq}: the {what} has no generated items: its {len(computed)} items are "
                                   f"computed from its polygon, spacing and angle", severity="warning")
        for command, frame, params in computed:
            self.mission.items.append(MissionItem(self.seq, command, frame, params, line, origin=origin))
            self.seq += 1

    def items(self, items: Any, line: int) -> None:
        if not isinstance(items, list):
            self.mission.problem(line, "the mission needs a list of \"items\"")
            return
        for item in items:
            kind = item.get("type") if isinstance(item, dict) else None
            where = _line(item, line)
            if kind == "SimpleItem":
                self.simple(item, where)
            elif kind == "ComplexItem":
                self.complex(item, where)
            else:
                self.mission.problem(where, f"item {self.seq}: an item is a SimpleItem or a ComplexItem, not "
                                            f"{kind if isinstance(kind, str) else type(item).__name__}")
                self.seq += 1
        if not self.mission.items and not self.mission.errors:
            self.mission.problem(line, "the mission has no items: nothing to fly")


def _home(mission: ItemMission, value: Any, line: int) -> None:
    if isinstance(value, dict):  # the legacy form: {"coordinate": [...]}
        value = value.get("coordinate")
    where = _numbers(value, 3)
    if where is None:
        if value is not None:
            mission.problem(line, "the plannedHomePosition is [latitude, longitude, altitude AMSL]")
        return
    lat, lon, alt = where
    if lat == 0.0 and lon == 0.0:
        return  # written by tools that had no home: no home
    why = valid_latitude_longitude(lat, lon)
    if why:
        mission.problem(line, f"the plannedHomePosition is no place on Earth: {why}", kind=WRONG_VALUE)
        return
    mission.home, mission.home_line = (lat, lon, 0.0 if math.isnan(alt) else alt), line


def _point(value: Any) -> tuple[float, float] | None:
    where = _numbers(value[:2] if isinstance(value, list) else value, 2)
    if where is None or valid_latitude_longitude(*where):
        return None
    return where


def _fences(mission: ItemMission, fence: Any, line: int) -> None:
    if not isinstance(fence, dict):
        return
    line = _line(fence, line)
    polygons = list(fence.get("polygons") or [])
    if isinstance(fence.get("polygon"), list) and fence["polygon"]:  # version 1: one inclusion polygon
        polygons.append({"polygon": fence["polygon"], "inclusion": True})
    for polygon in polygons:
        where = _line(polygon, line)
        vertices = [_point(p) for p in polygon.get("polygon") or []] if isinstance(polygon, dict) else []
        if not vertices:
            continue  # an empty polygon: QGroundControl's way of writing none
        if len(vertices) < 3 or None in vertices:
            mission.problem(where, "a geofence polygon needs 3 or more [latitude, longitude] points on Earth")
            continue
        mission.fences.append(GeoFence(bool(polygon.get("inclusion", True)), tuple(vertices), line=where))
    for circle in fence.get("circles") or []:
        where = _line(circle, line)
        shape = circle.get("circle") if isinstance(circle, dict) else None
        center = _point(shape.get("center")) if isinstance(shape, dict) else None
        radius = number(shape.get("radius")) if isinstance(shape, dict) else math.nan
        if center is None or not radius > 0:
            mission.problem(where, "a geofence circle needs a center [latitude, longitude] and a radius > 0")
            continue
        mission.fences.append(GeoFence(bool(circle.get("inclusion", True)), center=center, radius=radius,
                                       line=where))


def _rally(mission: ItemMission, rally: Any, line: int) -> None:
    if not isinstance(rally, dict):
        return
    for point in rally.get("points") or []:
        where = _numbers(point, 3)
        if where is None or valid_latitude_longitude(where[0], where[1]) or math.isnan(where[2]):
            mission.problem(_line(rally, line), f"a rally point is [latitude, longitude, altitude], not {point!r}")
        else:
            mission.rally.append((where, _line(rally, line)))


def _vehicle(mission: ItemMission, plan: dict, line: int) -> None:
    vehicle = plan.get("vehicleType")
    if isinstance(vehicle, int) and not isinstance(vehicle, bool) and vehicle not in MULTICOPTERS:
        what = VEHICLE_TYPES.get(vehicle, f"a vehicle of MAV_TYPE {vehicle}")
        mission.problem(line, f"the plan was made for {what} (vehicleType {vehicle}): aeroexec flies multicopters")
    mission.ardupilot = plan.get("firmwareType") == ARDUPILOT


def read_plan(text: str, file: str) -> ItemMission:
    """A ``.plan`` (QGroundControl's documented JSON, ``fileType: Plan``) as an item mission."""
    plan = parse_json(text, file)
    if not isinstance(plan, dict) or plan.get("fileType") != "Plan":
        raise TreeFormatError([(file, _line(plan, 1), "not a QGroundControl plan: \"fileType\" must be \"Plan\"")])
    mission = ItemMission(file, line=plan.line)
    if plan.get("version") != 1:
        mission.problem(plan.line, f"a plan of version {plan.get('version')!r}: QGroundControl writes version 1")
    body = plan.get("mission")
    if not isinstance(body, dict):
        mission.problem(plan.line, "the plan has no \"mission\": nothing to fly")
        return mission
    mission.line = body.line
    if body.get("version") != 2:
        mission.problem(body.line, f"a plan's mission of version {body.get('version')!r}: QGroundControl writes "
                                   f"version 2")
    _vehicle(mission, body, body.line)
    _home(mission, body.get("plannedHomePosition"), body.line)
    _fences(mission, plan.get("geoFence"), plan.line)
    _rally(mission, plan.get("rallyPoints"), plan.line)
    if not mission.errors:
        _PlanReader(mission).items(body.get("items"), body.line)
    return mission


def read_legacy_mission(text: str, file: str) -> ItemMission:
    """QGroundControl's legacy ``.mission`` JSON (``items`` and ``plannedHomePosition`` at the top)."""
    document = parse_json(text, file)
    if not isinstance(document, dict) or "items" not in document:
        raise TreeFormatError([(file, _line(document, 1), "not a QGroundControl .mission: it needs \"items\" (or "
                                                          "the first line \"QGC WPL 110\")")])
    mission = ItemMission(file, line=document.line)
    _vehicle(mission, document, document.line)
    _home(mission, document.get("plannedHomePosition"), document.line)
    _PlanReader(mission).items(document.get("items"), document.line)
    return mission
