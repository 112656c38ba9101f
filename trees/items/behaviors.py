"""Mission items as a behavior tree of the catalog's behaviors: one mapping for every item file.

Positions become geographic points (``geo:LAT,LON,ALT``, altitude above home), placed in the flying drone's frame
when each behavior starts, so a plan flies where it is planned whatever the vehicle's home; altitudes AMSL are
taken from the home the mission is placed from. Items and the behaviors they become:

| items | behaviors |
|---|---|
| NAV_TAKEOFF | TAKE_OFF (then GO_TO_POINT to its place on PX4 plans) |
| NAV_WAYPOINT, NAV_SPLINE_WAYPOINT (flown straight) | GO_TO_POINT (SPEED, yaw, acceptance radius, ROI), WAIT its hold |
| NAV_LOITER_TIME, _TURNS, _UNLIM | GO_TO_POINT, then WAIT / KEEP_LOITERING for the turns / KEEP_HOVERING |
| NAV_LAND, NAV_RETURN_TO_LAUNCH | GO_TO_POINT above the place (home or the nearest rally point), LAND |
| NAV_DELAY, CONDITION_DELAY | WAIT |
| CONDITION_YAW, CONDITION_CHANGE_ALT | ROTATE, GO_TO_POINT up or down |
| CONDITION_DISTANCE | the following DO items run at that distance before the next waypoint |
| DO_JUMP | Repeat over the items jumped back over |
| DO_CHANGE_SPEED | the SPEED of the GO_TO_POINTs after it |
| DO_SET_ROI(_LOCATION), DO_SET_ROI_NONE | LOOK_AT_A_POINT; the flights after it face the point until none |
| DO_DIGICAM_CONTROL, IMAGE_START_CAPTURE (one) | TAKE_PHOTO |
| DO_SET_CAM_TRIGG_DIST/INTERVAL, IMAGE_START/STOP_CAPTURE | TRIGGER_CAMERA beside the items until stopped |
| VIDEO_START/STOP_CAPTURE | RECORD_VIDEO beside the items until stopped |
| DO_GRIPPER | DROP_ITEM (release) |

Items that change nothing aeroexec acts on (a camera mode, a mount angle, a landing marker) are warnings naming
them; fixed-wing and VTOL items, and items that drive hardware aeroexec has not, are errors saying why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from aeroexec.drones.angles import wrap180
from aeroexec.drones.geodesy import Geodetic, enu_to_geodetic, format_geo, geo_to_enu
from aeroexec.drones.sim.geofence import Fence
from aeroexec.engine.errors import WRONG_SEQUENCE, WRONG_VALUE, MissionProblem, Problem
from aeroexec.trees.items.commands import CommandItems, text
from aeroexec.trees.items.model import ABSOLUTE_FRAMES, GLOBAL_FRAMES, POSITIONAL, REFUSED, ItemMission, MissionItem
from aeroexec.trees.items.structure import Span, Step, build, nest_jumps
from aeroexec.trees.model import TreeDocument, TreeNode

Vector = tuple[float, float, float]
MIN_RETURN_ALTITUDE = 2.0  # m: a return to launch flies home at the altitude it flies at, this at the least
LOITER_SPEED = 2.0  # m/s KEEP_LOITERING flies circles of 4 m radius and more at
NOTHING_TO_ACT_ON = {189: "marks where a landing sequence starts; aeroexec's returns fly home",
                     205: "points a camera mount; the simulated camera keeps its own pitch",
                     530: "sets the camera's mode; the simulated camera takes photos and videos in any mode",
                     531: "zooms the camera; the simulated camera has a fixed lens",
                     532: "focuses the camera; the simulated camera is always in focus",
                     1000: "points a gimbal; the simulated camera keeps its own pitch"}





@dataclass
class PlanDocument(TreeDocument):
    """A mission-item file as a tree, with what it says besides (fences and rally points in ENU meters from
    ``home``) and what was found wrong with it (each with its item number and line)."""

    fences: list[Fence] = field(default_factory=list)
    rally_points: list[Vector] = field(default_factory=list)
    problems: list[MissionProblem] = field(default_factory=list)
    home: Geodetic | None = None  # where the mission was placed from (latitude, longitude, altitude AMSL)
    mission: ItemMission | None = None
    item_lines: dict[int, int] = field(default_factory=dict)  # file line -> item number

    def numbered(self, problems: list[Problem]) -> list[Problem]:
        """``problems`` with the item number of their line in front ("item 4: ..."), as every message has it."""
        numbered = []
        for p in problems:
            seq = self.item_lines.get(p.line) if p.file == self.file else None
            if seq is not None and not p.message.startswith("item "):
                p = MissionProblem(p.severity, f"item {seq}: {p.message}", p.file, p.line,
                                   getattr(p, "kind", ""), getattr(p, "column", 0))
            numbered.append(p)
        return numbered


class _Converter(CommandItems):
    """The items, in order, into entries of the tree (one state: where the drone will be, how it flies)."""

    def __init__(self, mission: ItemMission, home: Geodetic, document: PlanDocument) -> None:
        self.mission, self.home, self.document, self.file = mission, home, document, mission.file
        self.entries: list = []
        self.nodes: list[TreeNode] = []  # the current item's
        self.position: Vector | None = None  # ENU; None: on the ground
        self.xy = (0.0, 0.0)
        self.speed: float | None = None
        self.roi: str | None = None
        self.distance_before: float | None = None  # CONDITION_DISTANCE pending
        self.held: list = []  # DO items waiting for the next waypoint (CONDITION_DISTANCE)
        self.jump_ids = {i.jump_id: i.seq for i in mission.items if i.jump_id is not None}

    # -- reporting -------------------------------------------------------------------------------------------
    def problem(self, item: MissionItem, message: str, severity: str = "error", kind: str = "WRONG_FORMAT") -> None:
        origin = f" ({item.origin})" if item.origin else ""
        self.document.problems.append(MissionProblem(severity, f"item {item.seq}{origin}: {message}", self.file,
                                                     item.line, kind))

    def node(self, kind: str, item: MissionItem, label: str, **ports: str) -> TreeNode:
        node = TreeNode(kind, f"item {item.seq} {label}", dict(ports), [], self.file, item.line)
        self.nodes.append(node)
        return node

    # -- places ----------------------------------------------------------------------------------------------
    def altitude(self, item: MissionItem, keep_zero: bool = False) -> float | None:
        """The item's altitude above home (None, reported, when it cannot be flown at)."""
        alt = item.altitude
        if math.isnan(alt) or (alt == 0.0 and self.mission.ardupilot and not keep_zero):
            return self.position[2] if self.position else 0.0  # "the altitude it flies at"
        if item.frame in ABSOLUTE_FRAMES:
            if alt < self.home[2] and not keep_zero:
                self.problem(item, f"{item.name} at {alt:g} m above sea level is below home ({self.home[2]:g} m "
                                   f"above sea level)", kind=WRONG_VALUE)
                return None
            return alt - self.home[2]
        if alt < 0 and not keep_zero:
            self.problem(item, f"{item.name} at {alt:g} m is below home (the take-off point)", kind=WRONG_VALUE)
            return None
        return alt

    def place(self, item: MissionItem, flown: bool = True) -> tuple[Vector, str] | None | bool:
        """The item's position (ENU, and its ``geo:`` text); None: it names none ("here"); False: reported.
        ``flown``: its altitude is flown at (a landing's is not)."""
        if item.frame not in GLOBAL_FRAMES:
            self.problem(item, f"{item.name} in MAV_FRAME {item.frame}: only global frames (0, 3, 5, 6, 10, 11) "
                               f"place an item on Earth")
            return False
        if not item.has_position():
            return None
        lat, lon = item.latitude, item.longitude
        if not (-90 <= lat <= 90 and -180 <= lon <= 180):
            self.problem(item, f"{item.name} at latitude {lat:g}, longitude {lon:g}: no place on Earth",
                         kind=WRONG_VALUE)
            return False
        alt = self.altitude(item) if flown else 0.0
        if alt is None:
            return False
        east, north, up = geo_to_enu((lat, lon, alt), self.home)
        return (east, north, up), format_geo(lat, lon, alt)

    def here(self, altitude: float) -> tuple[Vector, str]:
        lat, lon, _ = enu_to_geodetic((*self.xy, 0.0), self.home)
        return (*self.xy, altitude), format_geo(lat, lon, altitude)

    def airborne(self, item: MissionItem, altitude: float) -> None:
        if self.position is None:
            self.problem(item, f"the mission flies to {item.name} from the ground: aeroexec takes off to "
                               f"{text(altitude)} m first", severity="warning")
            take_off = TreeNode("TAKE_OFF", f"item {item.seq} take-off", {"ALTITUDE": text(max(altitude, 0.5))},
                                [], self.file, item.line)
            # an entry of its own, before the item's: a DO_JUMP back to the item repeats the flight, not the take-off
            self.entries.append(Step(item.seq - 0.5, [take_off]))  # type: ignore[arg-type]
            self.position = (*self.xy, altitude)

    def go_to(self, item: MissionItem, label: str, where: tuple[Vector, str], yaw: float = math.nan,
              accept: float = math.nan) -> None:
        point, geo = where
        if self.distance_before is not None and self.held:
            self._release_held(item, point)
        ports = {"COORDINATES": geo}
        if self.speed is not None:
            ports["SPEED"] = text(self.speed)
        if self.roi is not None:
            ports["POINT_TO_LOOK_DURING_FLIGHT"] = self.roi
        elif not math.isnan(yaw):
            ports["YAW_ANGLE_AT_THE_END"] = text(wrap180(90.0 - yaw))  # MAVLink: 0 north, clockwise
        if accept > 0:
            ports["ACCEPTANCE_RADIUS"] = text(accept)
        self.node("GO_TO_POINT", item, label, **ports)
        self.position, self.xy = point, point[:2]

    def _release_held(self, item: MissionItem, target: Vector) -> None:
        """CONDITION_DISTANCE: fly to ``distance_before`` meters short of ``target``, run the held DO items."""
        start, leg = self.position or (*self.xy, target[2]), math.dist(self.position or target, target)
        if leg > self.distance_before:
            f = 1.0 - self.distance_before / leg
            point = tuple(a + (b - a) * f for a, b in zip(start, target, strict=True))
            lat, lon, _ = enu_to_geodetic((point[0], point[1], 0.0), self.home)
            self.node("GO_TO_POINT", item, f"{self.distance_before:g} m before it",
                      COORDINATES=format_geo(lat, lon, point[2]), **({"SPEED": text(self.speed)} if self.speed
                                                                      else {}))
        self.entries.append(Step(item.seq, self.nodes))
        self.entries.extend(self.held)
        self.nodes, self.held, self.distance_before = [], [], None

    # -- one item ----------------------------------------------------------------------------------------------
    def item(self, item: MissionItem) -> None:
        self.nodes = []
        handler = getattr(self, f"_{item.name.lower()}", None)
        params = item.params
        if item.command in REFUSED:
            self.problem(item, f"{item.name} {REFUSED[item.command]}: the mission cannot fly as written")
        elif item.command in NOTHING_TO_ACT_ON:
            self.problem(item, f"{item.name} {NOTHING_TO_ACT_ON[item.command]}: nothing to do", severity="warning")
        elif handler is None:
            self.problem(item, f"{item.name} has no behavior in aeroexec: the mission cannot fly as written")
        else:
            handler(item, params)
        if self.nodes:
            self.emit(Step(item.seq, self.nodes), item)
        self.nodes = []

    def emit(self, entry: Step | Span, item: MissionItem) -> None:
        """An entry of the tree, or held for the next waypoint when a CONDITION_DISTANCE says so (DO items)."""
        if self.distance_before is not None and item.command >= 176:
            self.held.append(entry)
        else:
            self.entries.append(entry)

    def _nav_waypoint(self, item: MissionItem, params: tuple[float, ...]) -> None:
        where = self.place(item)
        if where is False:
            return
        if where is None:
            alt = self.altitude(item)
            if alt is None:
                return
            where = self.here(alt)
        self.airborne(item, where[0][2])
        yaw = math.nan if self.mission.ardupilot and params[3] == 0 else params[3]  # ArduPilot writes 0: none
        self.go_to(item, item.name.removeprefix("NAV_"), where, yaw, params[1])
        if params[0] > 0:
            self.node("WAIT", item, "hold", DURATION=text(params[0]))

    def _nav_spline_waypoint(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self.problem(item, "NAV_SPLINE_WAYPOINT is flown as a straight NAV_WAYPOINT", severity="warning")
        self._nav_waypoint(item, params)

    def _nav_takeoff(self, item: MissionItem, params: tuple[float, ...]) -> None:
        where = self.place(item) if not self.mission.ardupilot else None  # ArduCopter climbs where it stands
        if where is False:
            return
        altitude = self.altitude(item, keep_zero=True) if not math.isnan(item.altitude) else None
        if altitude is None or altitude <= 0:
            self.problem(item, "NAV_TAKEOFF without an altitude (param7)" if math.isnan(item.altitude) else
                         f"NAV_TAKEOFF to {item.altitude:g} m: a take-off climbs above home", kind=WRONG_VALUE)
            return
        if self.position is not None:
            self.problem(item, "a take-off while flying", kind=WRONG_SEQUENCE)
        self.node("TAKE_OFF", item, "TAKEOFF", ALTITUDE=text(altitude))
        self.position = (*self.xy, altitude)
        if where is not None and math.dist(where[0][:2], self.xy) > 1.0:
            point, _ = where
            lat, lon = item.latitude, item.longitude
            self.go_to(item, "TAKEOFF place", ((point[0], point[1], altitude), format_geo(lat, lon, altitude)))

    def _nav_loiter_time(self, item: MissionItem, params: tuple[float, ...], then: str = "WAIT") -> None:
        where = self.place(item)
        if where is False:
            return
        if where is None and self.position is not None and not math.isnan(item.altitude) and item.altitude != 0:
            altitude = self.altitude(item)  # here, at its altitude
            where = None if altitude is None else self.here(altitude)
        there = where is not None and (self.position is None or math.dist(where[0][:2], self.xy) > 0.5
                                       or abs(where[0][2] - self.position[2]) > 0.3)
        if there:
            self.airborne(item, where[0][2])
            self.go_to(item, item.name.removeprefix("NAV_"), where)
        if then == "WAIT":
            self.node("WAIT", item, "loiter", DURATION=text(max(params[0], 0.0)))

    def _nav_loiter_unlim(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self._nav_loiter_time(item, params, then="")
        self.problem(item, "NAV_LOITER_UNLIM holds there until the operator moves the mission on (aeroexec ctl "
                           "skip, or the console)", severity="warning")
        self.node("KEEP_HOVERING", item, "loiter")

    def _nav_loiter_turns(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self._nav_loiter_time(item, params, then="")
        radius = abs(params[2]) if params[2] and not math.isnan(params[2]) else 2.0
        turns = max(params[0], 0.0)
        speed = min(LOITER_SPEED, max(0.5, 0.5 * radius))
        seconds = turns * 2.0 * math.pi * radius / speed
        loiter = TreeNode("KEEP_LOITERING", f"item {item.seq} circle", {"SHAPE": "CIRCLE", "RADIUS": text(radius),
                                                                       "CLOCKWISE": str(params[2] >= 0).lower()},
                          [], self.file, item.line)
        wait = TreeNode("WAIT", f"item {item.seq} {text(turns)} turns", {"DURATION": text(seconds)}, [],
                        self.file, item.line)
        self.nodes.append(TreeNode("Parallel", f"item {item.seq} LOITER_TURNS",
                                   {"success_count": "1", "failure_count": "1"}, [loiter, wait], self.file, item.line))

    def _nav_land(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if item.has_position():
            where = self.place(item, flown=False)
            if where is False:
                return
            if self.position is not None and math.dist(where[0][:2], self.xy) > 0.5:
                lat, lon = item.latitude, item.longitude
                self.go_to(item, "above the landing place",
                           ((*where[0][:2], self.position[2]), format_geo(lat, lon, self.position[2])))
        self.node("LAND", item, "LAND")
        self.position = None

    def _nav_return_to_launch(self, item: MissionItem, params: tuple[float, ...]) -> None:
        rally = [(p, geo) for p, geo in zip(self.document.rally_points, self._rally_geo(), strict=True)]
        places = [((0.0, 0.0, 0.0), None), *rally]
        target, geo = min(places, key=lambda p: math.dist(p[0][:2], self.xy))
        altitude = max(self.position[2] if self.position else 0.0, MIN_RETURN_ALTITUDE)
        if self.position is not None and math.dist(target[:2], self.xy) > 0.5:
            place = text(0.0, 0.0, altitude) if geo is None else format_geo(geo[0], geo[1], altitude)
            self.go_to(item, "return", ((target[0], target[1], altitude), place))
        self.node("LAND", item, "land")
        self.position = None

    def _rally_geo(self) -> list[tuple[float, float]]:
        return [(lat, lon) for (lat, lon, _), _ in self.mission.rally]

    def _nav_delay(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[0] < 0:
            self.problem(item, "NAV_DELAY until a time of day: aeroexec waits seconds, not clock times")
            return
        self.node("WAIT", item, "delay", DURATION=text(params[0]))

    def finish(self) -> list[TreeNode]:
        """The tree's nodes once every item is in."""
        self.entries.extend(self.held)
        if self.position is not None:
            last = self.mission.items[-1]
            self.document.problems.append(MissionProblem(
                "warning", f"item {last.seq}: the mission ends in the air (no NAV_LAND or NAV_RETURN_TO_LAUNCH): "
                           f"aeroexec lands the drone where it is when the mission ends", self.file, last.line))

        def problem(line: int, message: str, severity: str = "error") -> None:
            self.document.problems.append(MissionProblem(severity, message, self.file, line, WRONG_SEQUENCE))

        return build(nest_jumps(self.entries, problem), self.file)


def mission_home(mission: ItemMission) -> Geodetic | None:
    """Where the mission says home is: its home, else below its first item with a place (None: it has none)."""
    if mission.home is not None:
        return mission.home
    first = next((i for i in mission.items if i.command in POSITIONAL and i.has_position()
                  and -90 <= i.latitude <= 90 and -180 <= i.longitude <= 180), None)
    return None if first is None else (first.latitude, first.longitude, 0.0)


def items_document(mission: ItemMission, home: Geodetic | None = None) -> PlanDocument:
    """The tree of ``mission``, placed from ``home`` (the world's; default: the mission's own home)."""
    from aeroexec.drones.sim.geofence import Fence

    own = mission_home(mission)
    if home is None:
        home = own
        if own is not None and mission.home is None:
            mission.problem(mission.items[0].line if mission.items else mission.line,
                            f"the file gives no home position: home is taken below item "
                            f"{next(i.seq for i in mission.items if i.has_position())} ({own[0]:.7f}, {own[1]:.7f}); "
                            f"--home LAT,LON places it elsewhere", severity="warning")
    if home is None:
        from aeroexec.drones.sim import default_world

        home = default_world().home
    elif own is not None and mission.home is not None:
        east, north, _ = geo_to_enu((own[0], own[1], 0.0), home)
        if math.hypot(east, north) > 5.0:
            mission.problem(mission.home_line or mission.line,
                            f"the mission's home is {math.hypot(east, north):.0f} m from the home it flies from "
                            f"({home[0]:.6f}, {home[1]:.6f}): the drone takes off there and flies to the items' "
                            f"latitudes and longitudes", severity="warning", kind=WRONG_VALUE)
    main = mission.file.rsplit("/", 1)[-1].rsplit(".", 1)[0] or "mission"
    document = PlanDocument({}, main, mission.file, {main: mission.line}, problems=list(mission.problems),
                            home=home, mission=mission, item_lines={})
    for item in mission.items:  # the items a survey generated share its line: the survey's own number
        document.item_lines.setdefault(item.line, item.seq)
    for fence in mission.fences:
        if fence.center is not None:
            east, north, _ = geo_to_enu((*fence.center, 0.0), home)
            document.fences.append(Fence(fence.inclusion, center=(east, north), radius=fence.radius, line=fence.line))
        else:
            vertices = tuple(geo_to_enu((lat, lon, 0.0), home)[:2] for lat, lon in fence.vertices)
            document.fences.append(Fence(fence.inclusion, vertices, line=fence.line))
    document.rally_points = [geo_to_enu(point, home) for point, _ in mission.rally]
    converter = _Converter(mission, home, document)
    for item in mission.items:
        converter.item(item)
    document.trees[main] = TreeNode("Sequence", main, {}, converter.finish(), mission.file, mission.line)
    document.problems = _grouped(document.problems)
    if not document.root.children and not any(p.severity == "error" for p in document.problems):
        document.problems.append(MissionProblem("error", "no item of the mission has a behavior: nothing to fly",
                                                mission.file, mission.line))
    return document


SAME_SAID = 3  # items with the same problem: this many are listed, the others counted


def _grouped(problems: list[MissionProblem]) -> list[MissionProblem]:
    """The problems, those that repeat one message for many items said for the first few and counted after."""
    import re

    def gist(p: MissionProblem) -> str:
        return re.sub(r"^item \d+( \([^)]*\))?: ", "", p.message)

    counts: dict[tuple[str, str], int] = {}
    for p in problems:
        counts[(p.severity, gist(p))] = counts.get((p.severity, gist(p)), 0) + 1
    kept, seen = [], {}
    for p in problems:
        key = (p.severity, gist(p))
        seen[key] = seen.get(key, 0) + 1
        if counts[key] <= SAME_SAID + 1 or seen[key] < SAME_SAID:
            kept.append(p)
        elif seen[key] == SAME_SAID:
            kept.append(MissionProblem(p.severity, f"{p.message.split(':')[0]} and {counts[key] - SAME_SAID} more "
                                                   f"items after it: {gist(p)}", p.file, p.line, p.kind))
    return kept
