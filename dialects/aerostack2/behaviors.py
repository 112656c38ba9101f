"""Aerostack2's behaviors as catalog requests: the modules of its Python API, their methods and arguments as
Aerostack2 declares them, and the request of the catalog each call stands for.

One table serves every way an Aerostack2 mission reaches aeroexec: the Python API (``aerostack/as2_python_api``),
the static check of its scripts, the mission interpreter's JSON/YAML plans and its behavior-tree nodes. A call is
bound like Python binds it (:meth:`Method.bind`), then turned into catalog requests (:func:`requests`):

========================  ===============================================================================
Aerostack2                the catalog's request
========================  ===============================================================================
``takeoff(height)``       ``TAKE_OFF ALTITUDE=height`` (the take-off speed is the vehicle's own)
``go_to(x, y, z, speed)`` ``GO_TO_POINT COORDINATES=(x, y, z) SPEED=speed``; ``navigate_to`` and
                          ``follow_reference`` too (GO_TO_POINT plans around obstacles here)
``follow_path(path, s)``  ``FOLLOW_PATH PATH=path SPEED=s``
``land(speed)``           ``LAND`` (the landing speed is the vehicle's own)
``rtl(height, speed, l)`` ``GO_TO_POINT COORDINATES=(0, 0, height)`` then ``LAND``
``go_to_gps(lat, lon..)`` ``GO_TO_POINT`` at the point's ENU coordinates from the GPS origin (the home point)
``point_gimbal(x, y, z)`` ``LOOK_AT_A_POINT COORDINATES=(x, y, z)`` (the drone turns: there is no gimbal)
========================  ===============================================================================

Yaw modes: ``FIXED_YAW`` ends facing ``yaw_angle`` (radians, ENU: 0 east, counterclockwise, as aeroexec's degrees);
``KEEP_YAW`` ends facing the yaw the drone had when asked (when known); ``PATH_FACING`` faces the travel, as
aeroexec's motion behaviors do by default. Coordinates are in the ``earth`` frame, aeroexec's local ENU frame;
other ROS 2 tf frames are refused.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from aeroexec.dialects import ros_messages
from aeroexec.dialects.ros import ROS2_BEYOND
from aeroexec.engine.errors import WRONG_FORMAT, WRONG_VALUE

KEEP_YAW, PATH_FACING, FIXED_YAW = 0, 1, 2
#: The frames that are aeroexec's local ENU frame (Aerostack2's default ``earth`` frame, and none given).
EARTH_FRAMES = ("", "earth", "/earth")


class As2Error(ValueError):
    """A call Aerostack2 would refuse, or aeroexec cannot serve: ``kind`` is WRONG_FORMAT or WRONG_VALUE."""

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind, self.message = kind, message


@dataclass(frozen=True)
class Method:
    """A method of an Aerostack2 module: its parameters (in order), their defaults, and the yaw mode it stands for
    (None: the caller gives ``yaw_mode``)."""

    module: str
    name: str
    parameters: tuple[str, ...]
    defaults: Mapping[str, Any] = field(default_factory=dict)
    yaw_mode: int | None = None
    #: Earlier names of parameters, still taken by keyword: Aerostack2's go_to, follow_reference and point_gimbal
    #: wrote x, y, z as _x, _y, _z until May 2024 (as2_python_api 71859358).
    spelled_before: Mapping[str, str] = field(default_factory=dict)

    def named(self, given: str) -> str:
        """The parameter a keyword argument names (its earlier spelling names today's)."""
        return given if given in self.parameters else self.spelled_before.get(given, given)

    @property
    def spelled(self) -> str:
        return self.module if self.name == "__call__" else f"{self.module}.{self.name}"

    def bind(self, args: Sequence[Any] = (), kwargs: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The arguments by parameter name, defaults filled in, as Python would bind them; As2Error otherwise."""
        kwargs = dict(kwargs or {})
        if len(args) > len(self.parameters):
            raise As2Error(WRONG_FORMAT, f"{self.spelled}() takes {len(self.parameters)} arguments "
                                         f"({', '.join(self.parameters)}), {len(args)} given")
        bound = dict(zip(self.parameters, args, strict=False))
        for given, value in kwargs.items():
            name = self.named(given)
            if name not in self.parameters:
                raise As2Error(WRONG_FORMAT, f"{self.spelled}() has no argument {given} "
                                             f"(its arguments: {', '.join(self.parameters)})")
            if name in bound:
                raise As2Error(WRONG_FORMAT, f"{self.spelled}() got two values for argument {name}")
            bound[name] = value
        for name in self.parameters:
            if name not in bound:
                if name not in self.defaults:
                    raise As2Error(WRONG_FORMAT, f"{self.spelled}() needs argument {name}")
                bound[name] = self.defaults[name]
        return bound


@dataclass(frozen=True)
class Request:
    """One catalog request an Aerostack2 call stands for; ``wait``: the call blocks until it ends."""

    behavior: str
    arguments: dict[str, Any]
    wait: bool = True


def _methods(module: str, table: Mapping[str, str], spelled_before: Mapping[str, str] | None = None,
             ) -> dict[str, Method]:
    """Methods from their Python signatures as Aerostack2 writes them (``"x, y, speed=0.5"``); ``spelled_before``:
    earlier names of their parameters (:attr:`Method.spelled_before`)."""
    methods = {}
    for name, signature in table.items():
        function = ast.parse(f"def f({signature}): pass").body[0]
        names = tuple(a.arg for a in function.args.args)
        defaults = {n: ast.literal_eval(d) for n, d in zip(names[len(names) - len(function.args.defaults):],
                                                              function.args.defaults, strict=True)}
        yaw = None if "yaw_mode" in names else FIXED_YAW if "with_yaw" in name else \
            PATH_FACING if "facing" in name else KEEP_YAW
        methods[name] = Method(module, name, names, defaults, yaw, dict(spelled_before or {}))
    return methods


_POINT_METHODS = {"": "x, y, z, speed, frame_id=None", "_with_yaw": "x, y, z, speed, angle, frame_id=None",
                  "_path_facing": "x, y, z, speed, frame_id=None", "_point": "point, speed, frame_id=None",
                  "_point_with_yaw": "point, speed, angle, frame_id=None",
                  "_point_path_facing": "point, speed, frame_id=None"}
_GPS_METHODS = {"": "lat, lon, alt, speed", "_with_yaw": "lat, lon, alt, speed, angle",
                "_path_facing": "lat, lon, alt, speed", "_point": "waypoint, speed",
                "_point_with_yaw": "waypoint, speed, angle", "_point_path_facing": "waypoint, speed"}
_REFERENCE = "x, y, z, frame_id, speed_x, speed_y, speed_z"
#: x, y, z as go_to, follow_reference and point_gimbal named them from February 2023 to May 2024 (_x, _y, _z).
_UNDERSCORED = {"_x": "x", "_y": "y", "_z": "z"}

#: Aerostack2's behavior modules by alias: method name -> Method (as in as2_python_api/modules/*_module.py).
MODULES: dict[str, dict[str, Method]] = {
    "takeoff": _methods("takeoff", {"__call__": "height=1.0, speed=0.5, wait=True"}),
    "land": _methods("land", {"__call__": "speed=0.5, wait=True"}),
    "go_to": _methods("go_to", {
        "__call__": "x, y, z, speed, yaw_mode=0, yaw_angle=None, frame_id=None, wait=True",
        **{f"go_to{suffix}": signature for suffix, signature in _POINT_METHODS.items()}}, _UNDERSCORED),
    "navigate_to": _methods("navigate_to", {
        "__call__": "x, y, z, speed, yaw_mode=2, yaw_angle=None, frame_id=None, wait=True",
        **{f"navigate_to{suffix}": signature for suffix, signature in _POINT_METHODS.items()}}),
    "follow_path": _methods("follow_path", {
        "__call__": "path, speed, yaw_mode=0, yaw_angle=None, frame_id=None, wait=True",
        "follow_path_with_keep_yaw": "path, speed, frame_id=None",
        "follow_path_with_yaw": "path, speed, angle, frame_id=None",
        "follow_path_with_path_facing": "path, speed, frame_id=None"}),
    "go_to_gps": _methods("go_to_gps", {
        "__call__": "lat, lon, alt, speed, yaw_mode=0, yaw_angle=None, wait=True",
        **{f"go_to_gps{suffix}": signature for suffix, signature in _GPS_METHODS.items()}}),
    "follow_path_gps": _methods("follow_path_gps", {
        "__call__": "geopath, speed, yaw_mode=0, yaw_angle=0.0, wait=True"}),
    # The spellings of Aerostack2 before 1.0 (go_to since February 2023): the module goto (x, y, z written _x, _y, _z),
    # goto_gps
    "goto": _methods("goto", {
        "__call__": "_x, _y, _z, speed, yaw_mode=2, yaw_angle=None, wait=True",
        "go_to": "_x, _y, _z, speed", "go_to_with_yaw": "_x, _y, _z, speed, angle",
        "go_to_path_facing": "_x, _y, _z, speed", "go_to_point": "point, speed",
        "go_to_point_with_yaw": "point, speed, angle", "go_to_point_path_facing": "point, speed"}),
    "goto_gps": _methods("goto_gps", {
        "__call__": "lat, lon, alt, speed, yaw_mode=2, yaw_angle=None, wait=True",
        **{f"go_to_gps{suffix}": signature for suffix, signature in _GPS_METHODS.items()}}),
    "rtl": _methods("rtl", {"__call__": "height, speed, land_speed, yaw_mode=0, yaw_angle=None, wait=True"}),
    "point_gimbal": _methods("point_gimbal", {"__call__": "x, y, z, frame_id, mode=0, wait=False",
                                              "point_gimbal": "x, y, z, frame_id, mode=0"}, _UNDERSCORED),
    "follow_reference": _methods("follow_reference", {
        "__call__": "x, y, z, frame_id, speed_x=0.0, speed_y=0.0, speed_z=0.0, yaw_mode=0, yaw_angle=None, "
                    "wait=False",
        "follow_reference": _REFERENCE, "follow_reference_with_yaw": f"{_REFERENCE}, angle",
        "follow_reference_with_reference_facing": _REFERENCE}, _UNDERSCORED),
}
#: What every module's behavior handler offers besides its methods (as2_python_api's BehaviorHandler).
HANDLER_MEMBERS = ("status", "feedback", "result", "result_status", "is_running", "start", "modify", "pause",
                   "resume", "stop", "wait_to_result", "destroy", "get_plan_item")
#: Aerostack2's drone interfaces: attribute -> the module alias it holds.
_FLIGHT = {"takeoff": "takeoff", "go_to": "go_to", "goto": "goto", "follow_path": "follow_path", "land": "land"}
INTERFACES: dict[str, dict[str, str]] = {
    "DroneInterfaceBase": {},
    "DroneInterface": _FLIGHT,
    "DroneInterfaceTeleop": {**_FLIGHT, "motion_ref_handler": "motion_ref_handler"},
    "DroneInterfaceGPS": {"gps": "gps", "takeoff": "takeoff", "go_to": "go_to_gps", "goto": "goto_gps",
                          "follow_path": "follow_path_gps", "land": "land"},
}
#: What every drone interface offers besides its modules (drone_interface_base.py).
DRONE_MEMBERS = ("arm", "disarm", "offboard", "manual", "shutdown", "load_module", "modules", "drone_id",
                 "namespace", "info", "position", "orientation", "speed", "earth_frame_id", "base_frame_id",
                 "send_emergency_land", "send_emergency_hover", "send_emergency_land_to_aircraft",
                 "send_emergency_hover_to_aircraft", "send_emergency_killswitch_to_aircraft", "get_logger",
                 "get_clock", "gps", "motion_ref_handler", "create_publisher", "destroy_publisher")


def method(module: str, name: str = "__call__") -> Method:
    """The method ``name`` of the module ``module``; As2Error when Aerostack2 has none."""
    methods = MODULES.get(module)
    if methods is None:
        raise As2Error(WRONG_FORMAT, f"The behavior module {module} does not exist in Aerostack2's Python API "
                                     f"(modules: {', '.join(MODULES)})")
    found = methods.get(name or "__call__")
    if found is None:
        raise As2Error(WRONG_FORMAT, f"The method {name} does not exist in Aerostack2's {module} module "
                                     f"(methods: {', '.join(methods)})")
    return found


_SAME = {"goto": "go_to", "goto_gps": "go_to_gps"}  # the modules of Aerostack2 before 1.0


def known(value: Any) -> bool:
    """A number (not a bool): what conversions can compute with; anything else passes through untouched."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def requests(call: Method, bound: Mapping[str, Any], *, home: Sequence[float] | None = None,
             yaw: float | None = None, frames: Sequence[Any] = ()) -> list[Request]:
    """The catalog requests a bound call stands for. ``home`` (latitude, longitude, altitude) places GPS points
    (without it they stay :class:`Unplaced`), ``yaw`` (degrees) is the drone's yaw now, which KEEP_YAW keeps,
    ``frames`` the world's named frames (:class:`~aeroexec.drones.sim.world.Frame`) a point may be given in.
    Values that are not numbers (not known before flight) pass through, so the static check judges the rest."""
    module, wait = _SAME.get(call.module, call.module), bool(bound.get("wait", True))
    frame = _check_frame(call, bound.get("frame_id"), frames)
    if frame is not None:
        bound = _in_earth(call, bound, frame)
    if module == "takeoff":
        return [Request("TAKE_OFF", {"ALTITUDE": bound["height"]}, wait)]
    if module == "land":
        return [Request("LAND", {}, wait)]
    if module == "rtl":
        home_point = (0.0, 0.0, bound["height"])
        return [Request("GO_TO_POINT", {"COORDINATES": home_point, **_yaw(call, bound, yaw),
                                        **_speed(bound["speed"])}), Request("LAND", {}, wait)]
    if module == "point_gimbal":
        return [Request("LOOK_AT_A_POINT", {"COORDINATES": _point(call, bound)}, wait)]
    if module in ("follow_path", "follow_path_gps"):
        path = bound["path" if module == "follow_path" else "geopath"]
        points = _path(call, path, home)
        return [Request("FOLLOW_PATH", {"PATH": points, **_speed(bound["speed"])}, wait)]
    if module == "follow_reference":
        speeds = [bound[k] for k in ("speed_x", "speed_y", "speed_z")]
        speed = max(speeds) if all(known(s) for s in speeds) else speeds[0]
        return [Request("GO_TO_POINT", {"COORDINATES": _point(call, bound), **_yaw(call, bound, yaw),
                                        **(_speed(speed) if not known(speed) or speed > 0 else {})}, wait)]
    if module == "go_to_gps":
        point = (_triple(call, bound["waypoint"], "waypoint", "[latitude, longitude, altitude]") if "waypoint" in bound
                 else (bound["lat"], bound["lon"], bound["alt"]))
        return [Request("GO_TO_POINT", {"COORDINATES": _from_gps(point, home), **_yaw(call, bound, yaw),
                                        **_speed(bound["speed"])}, wait)]
    return [Request("GO_TO_POINT", {"COORDINATES": _point(call, bound), **_yaw(call, bound, yaw),
                                    **_speed(bound["speed"])}, wait)]


def _check_frame(call: Method, frame: Any, frames: Sequence[Any] = ()) -> Any:
    """The world's frame ``frame`` names (None: the earth frame, or a frame not known before flight)."""
    if frame is None or not isinstance(frame, str) or frame.strip() in EARTH_FRAMES:
        return None
    name = frame.strip().lstrip("/")
    found = next((f for f in frames if f.name == name), None)
    if found is not None:
        return found
    known_frames = f" nor one of the world's ({', '.join(f.name for f in frames)})" if frames else ""
    raise As2Error(WRONG_VALUE, f"The frame {frame!r} of {call.spelled}() is not correct: aeroexec flies in the "
                                f"earth frame (local ENU from home){known_frames}; other frames of ROS 2's tf tree "
                                f"are not available ({ROS2_BEYOND})")


def _in_earth(call: Method, bound: Mapping[str, Any], frame: Any) -> dict[str, Any]:
    """``bound`` with its point or path given in ``frame`` moved into the earth frame (a value not known before
    flight passes through)."""
    moved = dict(bound)

    def place(value: Any) -> Any:
        value = ros_messages.point(value)
        if isinstance(value, list | tuple) and len(value) == 3 and all(known(v) for v in value):
            return list(frame.to_world(tuple(float(v) for v in value)))
        return value

    if "point" in moved:
        moved["point"] = place(moved["point"])
    elif all(k in moved and known(moved[k]) for k in ("x", "y", "z")):
        moved["x"], moved["y"], moved["z"] = frame.to_world((moved["x"], moved["y"], moved["z"]))
    if "path" in moved:
        path = ros_messages.points(moved["path"])
        if isinstance(path, list | tuple):
            moved["path"] = [place(p) for p in path]
    moved["frame_id"] = None
    return moved


def _point(call: Method, bound: Mapping[str, Any]) -> Any:
    if "point" in bound:
        return _triple(call, bound["point"], "point", "[x, y, z] in meters")
    return tuple(bound[k] if k in bound else bound[f"_{k}"] for k in ("x", "y", "z"))


def _triple(call: Method, value: Any, what: str, expected: str) -> Any:
    """A list of three values as a tuple (anything else not known before flight passes through)."""
    value = ros_messages.point(value)  # a geometry_msgs Point, Pose, PoseStamped: its position
    if not isinstance(value, list | tuple):
        return value
    if len(value) != 3:
        raise As2Error(WRONG_VALUE, f"The {what} {list(value)} of {call.spelled}() is not correct ({expected} is "
                                    f"expected)")
    return tuple(value)


def _speed(speed: Any) -> dict[str, Any]:
    """SPEED for the request: Aerostack2's max speed (None leaves the vehicle's cruise speed)."""
    return {} if speed is None else {"SPEED": speed}


def _yaw(call: Method, bound: Mapping[str, Any], yaw_now: float | None) -> dict[str, Any]:
    mode = call.yaw_mode if call.yaw_mode is not None else bound.get("yaw_mode", KEEP_YAW)
    if not known(mode):
        return {}
    if mode == FIXED_YAW:
        angle = bound.get("angle", bound.get("yaw_angle"))
        if angle is None:
            angle = 0.0  # Aerostack2 sends the goal's default angle
        return {"YAW_ANGLE_AT_THE_END": degrees(angle) if known(angle) else angle}
    if mode == KEEP_YAW:
        return {} if yaw_now is None else {"YAW_ANGLE_AT_THE_END": round(yaw_now, 3)}
    if mode == PATH_FACING:
        return {}
    raise As2Error(WRONG_VALUE, f"The yaw mode {mode} of {call.spelled}() is not supported: KEEP_YAW (0), "
                                f"PATH_FACING (1) and FIXED_YAW (2) are (modes 3 to 6 follow ROS 2 topics and frames)")


def degrees(angle: float) -> float:
    """Aerostack2's yaw (radians) as aeroexec's (degrees in [-180, 180), both ENU: 0 east, counterclockwise)."""
    value = math.degrees(angle)
    return round((value + 180.0) % 360.0 - 180.0, 6)


def _path(call: Method, path: Any, home: Sequence[float] | None) -> Any:
    path = ros_messages.points(path)  # a nav_msgs Path, a list of PoseStamped or PoseWithID: their positions
    if not isinstance(path, list | tuple):
        return path  # not known before flight (or a ROS message, refused by the API at run time)
    points = []
    for point in path:
        if isinstance(point, list | tuple) and len(point) == 3:
            points.append(_from_gps(tuple(point), home) if call.module.endswith("gps") else tuple(point))
        elif isinstance(point, list | tuple):
            raise As2Error(WRONG_VALUE, f"The point {list(point)} in the path of {call.spelled}() is not correct "
                                        f"([x, y, z] in meters is expected)")
        else:
            points.append(point)
    return tuple(points)


class Unplaced(tuple):
    """A GPS point (latitude, longitude, altitude) with no origin to place it from: known only in flight."""


def _from_gps(point: Any, home: Sequence[float] | None) -> Any:
    """ENU meters from ``home`` of (latitude, longitude, altitude); the altitude is meters above the origin, as
    Aerostack2's go_to_gps takes it. Without ``home`` the point stays :class:`Unplaced`."""
    if not isinstance(point, tuple) or not all(known(v) for v in point):
        return point
    if home is None:
        return Unplaced(point)
    from aeroexec.drones.geodesy import geodetic_to_enu

    east, north, _ = geodetic_to_enu((point[0], point[1], home[2]), tuple(home))
    return round(east, 3), round(north, 3), point[2]


__all__ = ["DRONE_MEMBERS", "EARTH_FRAMES", "FIXED_YAW", "HANDLER_MEMBERS", "INTERFACES", "KEEP_YAW", "MODULES",
           "PATH_FACING", "As2Error", "Method", "Request", "Unplaced", "degrees", "known",
           "method", "requests"]
