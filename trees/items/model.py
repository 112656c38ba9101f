"""The item model every mission-item file is read into: numbered MAVLink items with their file line, the mission's
home, geofence and rally points, in geographic coordinates (the placing in a world's ENU frame comes later).

Item numbers are the ones a ground station shows and uploads: 0 is home, the first item is 1, and each item a
survey generated has its own number. Parameters are MAVLink's seven (param1-4, then x/latitude, y/longitude,
z/altitude), NaN where the file says null.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from aeroexec.drones.geodesy import Geodetic
from aeroexec.engine.errors import WRONG_FORMAT, MissionProblem

#: MAV_CMD numbers and names of the items aeroexec reads (others are named by number).
COMMANDS = {
    16: "NAV_WAYPOINT", 17: "NAV_LOITER_UNLIM", 18: "NAV_LOITER_TURNS", 19: "NAV_LOITER_TIME",
    20: "NAV_RETURN_TO_LAUNCH", 21: "NAV_LAND", 22: "NAV_TAKEOFF", 23: "NAV_LAND_LOCAL", 24: "NAV_TAKEOFF_LOCAL",
    25: "NAV_FOLLOW", 30: "NAV_CONTINUE_AND_CHANGE_ALT", 31: "NAV_LOITER_TO_ALT", 80: "NAV_ROI",
    82: "NAV_SPLINE_WAYPOINT", 84: "NAV_VTOL_TAKEOFF", 85: "NAV_VTOL_LAND", 92: "NAV_GUIDED_ENABLE",
    93: "NAV_DELAY", 94: "NAV_PAYLOAD_PLACE", 112: "CONDITION_DELAY", 113: "CONDITION_CHANGE_ALT",
    114: "CONDITION_DISTANCE", 115: "CONDITION_YAW", 176: "DO_SET_MODE", 177: "DO_JUMP", 178: "DO_CHANGE_SPEED",
    179: "DO_SET_HOME", 181: "DO_SET_RELAY", 182: "DO_REPEAT_RELAY", 183: "DO_SET_SERVO", 184: "DO_REPEAT_SERVO",
    186: "DO_CHANGE_ALTITUDE", 189: "DO_LAND_START", 191: "DO_GO_AROUND", 195: "DO_SET_ROI_LOCATION",
    196: "DO_SET_ROI_WPNEXT_OFFSET", 197: "DO_SET_ROI_NONE", 200: "DO_CONTROL_VIDEO", 201: "DO_SET_ROI",
    202: "DO_DIGICAM_CONFIGURE", 203: "DO_DIGICAM_CONTROL", 205: "DO_MOUNT_CONTROL", 206: "DO_SET_CAM_TRIGG_DIST",
    207: "DO_FENCE_ENABLE", 208: "DO_PARACHUTE", 211: "DO_GRIPPER", 212: "DO_AUTOTUNE_ENABLE",
    214: "DO_SET_CAM_TRIGG_INTERVAL", 218: "DO_AUX_FUNCTION", 530: "SET_CAMERA_MODE", 531: "SET_CAMERA_ZOOM",
    532: "SET_CAMERA_FOCUS", 1000: "DO_GIMBAL_MANAGER_PITCHYAW", 2000: "IMAGE_START_CAPTURE",
    2001: "IMAGE_STOP_CAPTURE", 2003: "DO_TRIGGER_CONTROL", 2500: "VIDEO_START_CAPTURE", 2501: "VIDEO_STOP_CAPTURE",
    3000: "DO_VTOL_TRANSITION", 5000: "NAV_FENCE_RETURN_POINT", 5001: "NAV_FENCE_POLYGON_VERTEX_INCLUSION",
    5002: "NAV_FENCE_POLYGON_VERTEX_EXCLUSION", 5003: "NAV_FENCE_CIRCLE_INCLUSION",
    5004: "NAV_FENCE_CIRCLE_EXCLUSION", 5100: "NAV_RALLY_POINT",
}
#: Items that fly to (or name) a place: their latitude and longitude are positions.
POSITIONAL = {16, 17, 18, 19, 21, 22, 30, 31, 82, 84, 85, 94, 195, 201}
#: Frames whose x/y are latitude/longitude: AMSL altitude (0, 5), above home (3, 6), above terrain (10, 11).
ABSOLUTE_FRAMES = (0, 5)
RELATIVE_FRAMES = (3, 6, 10, 11)
GLOBAL_FRAMES = ABSOLUTE_FRAMES + RELATIVE_FRAMES
MISSION_FRAME = 2
#: MAV_TYPE of the vehicles a multicopter mission is for (quad, coaxial, heli, hexa, octo, tri, dodeca, deca).
MULTICOPTERS = {0, 2, 3, 4, 13, 14, 15, 29, 35}
VEHICLE_TYPES = {1: "a fixed-wing aircraft", 7: "an airship", 8: "a free balloon", 10: "a ground rover",
                 11: "a boat", 12: "a submarine", 19: "a VTOL", 20: "a VTOL", 21: "a VTOL", 22: "a VTOL",
                 23: "a VTOL", 24: "a VTOL", 25: "a VTOL", 16: "a flapping-wing aircraft", 17: "a kite",
                 28: "a parafoil"}
#: Why items of fixed-wing and VTOL aircraft, and items that drive hardware aeroexec has not, are refused.
REFUSED = {
    23: "is in a local frame the plan does not place", 24: "is in a local frame the plan does not place",
    25: "follows a target aeroexec does not track",
    30: "is a fixed-wing item (climb or descend while flying on)",
    31: "is a fixed-wing item (loiter until an altitude is reached)",
    84: "is a VTOL item (take off as a multicopter, then transition to forward flight)",
    85: "is a VTOL item (transition back and land as a multicopter)",
    92: "hands the vehicle over to an offboard computer", 94: "lowers a payload until it touches the ground: "
    "aeroexec's drone has no winch", 176: "changes the autopilot's flight mode", 179: "moves the home position",
    181: "switches a relay aeroexec does not drive", 182: "switches a relay aeroexec does not drive",
    183: "moves a servo aeroexec does not drive", 184: "moves a servo aeroexec does not drive",
    186: "is a fixed-wing item (change the cruise altitude)", 191: "is a fixed-wing item (abort a landing)",
    196: "points at the next waypoint with an offset aeroexec does not fly", 200: "drives a video transmitter",
    202: "configures a camera aeroexec does not drive", 207: "switches the autopilot's own geofence",
    208: "fires a parachute aeroexec's drone does not have", 212: "starts the autopilot's autotune",
    218: "switches an RC auxiliary function of the autopilot", 2003: "switches the camera trigger hardware",
    3000: "is a VTOL item (transition between multicopter and forward flight)",
    5000: "is a geofence return point: the file holds a geofence, not a mission",
    5001: "is a geofence vertex: the file holds a geofence, not a mission",
    5002: "is a geofence vertex: the file holds a geofence, not a mission",
    5003: "is a geofence circle: the file holds a geofence, not a mission",
    5004: "is a geofence circle: the file holds a geofence, not a mission",
    5100: "is a rally point: the file holds rally points, not a mission",
}


def number(value: object) -> float:
    """A JSON or text parameter as a float; NaN for null and anything that is no finite number."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return math.nan
    number = float(value)
    return number if math.isfinite(number) else math.nan


@dataclass
class MissionItem:
    """One mission item: its number, MAV_CMD, MAV_FRAME and seven parameters, where the file writes it."""

    seq: int
    command: int
    frame: int
    params: tuple[float, ...]  # param1..param4, latitude (x), longitude (y), altitude (z); NaN for null
    line: int = 0
    autocontinue: bool = True
    jump_id: int | None = None  # a .plan's doJumpId, which DO_JUMP names
    origin: str = ""  # "survey item 2" for the items a complex item generated

    @property
    def name(self) -> str:
        return COMMANDS.get(self.command, f"MAV_CMD {self.command}")

    @property
    def latitude(self) -> float:
        return self.params[4]

    @property
    def longitude(self) -> float:
        return self.params[5]

    @property
    def altitude(self) -> float:
        return self.params[6]

    def has_position(self) -> bool:
        """Latitude and longitude given and not both 0 (0, 0 means "where the drone is", as ArduPilot reads it)."""
        lat, lon = self.latitude, self.longitude
        return not (math.isnan(lat) or math.isnan(lon) or (lat == 0.0 and lon == 0.0))


@dataclass(frozen=True)
class GeoFence:
    """A geofence polygon (``vertices``: latitude, longitude) or circle (``center``, ``radius`` m)."""

    inclusion: bool
    vertices: tuple[tuple[float, float], ...] = ()
    center: tuple[float, float] | None = None
    radius: float = 0.0
    line: int = 0


@dataclass
class ItemMission:
    """A mission-item file as read: its items, home, geofence, rally points and what was wrong with it."""

    file: str
    items: list[MissionItem] = field(default_factory=list)
    home: Geodetic | None = None  # latitude, longitude, altitude AMSL
    home_line: int = 0
    line: int = 1  # where the mission's items start
    fences: list[GeoFence] = field(default_factory=list)
    rally: list[tuple[Geodetic, int]] = field(default_factory=list)  # (latitude, longitude, altitude), line
    ardupilot: bool = False  # ArduPilot's readings: 0, 0 is "here", altitude 0 of a waypoint is "this altitude"
    problems: list[MissionProblem] = field(default_factory=list)

    def problem(self, line: int, message: str, severity: str = "error", kind: str = WRONG_FORMAT) -> None:
        self.problems.append(MissionProblem(severity, message, self.file, line, kind))

    @property
    def errors(self) -> list[MissionProblem]:
        return [p for p in self.problems if p.severity == "error"]

    def places(self) -> list[tuple[float, float]]:
        """Every latitude/longitude the mission names: items, rally points, fences."""
        found = [(i.latitude, i.longitude) for i in self.items if i.command in POSITIONAL and i.has_position()]
        found += [(lat, lon) for (lat, lon, _), _ in self.rally]
        for fence in self.fences:
            found += list(fence.vertices) + ([fence.center] if fence.center else [])
        return found
