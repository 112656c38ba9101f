"""ROS 2 message types a mission uses as plain data: built, filled and read as ``rclpy`` builds them
(``PoseStamped()``, ``pose.pose.position.x = 1.0``, ``path.poses.append(pose)``), with nothing published.

The messages of ``builtin_interfaces``, ``std_msgs``, ``geometry_msgs``, ``nav_msgs``, ``sensor_msgs`` and
``geographic_msgs`` that missions build for their drone interface (a path of poses, a point, a GPS fix or path, an
LED colour) are here, by module
(:data:`MESSAGES`); :func:`points` reads a path or a point of them as the coordinates a behavior takes. A drone
interface's publisher puts them in the event log; subscribing still needs a ROS 2 graph, which these stand-ins
refuse (``dialects/ros.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class Message:
    """A ROS 2 message as data: its fields (defaults as ``rosidl`` makes them), set by keyword or attribute."""

    _fields: dict[str, Callable[[], Any]] = {}

    def __init__(self, **values: Any) -> None:
        unknown = set(values) - set(self._fields)
        if unknown:
            raise TypeError(f"{type(self).__name__}() has no field {sorted(unknown)[0]!r} (its fields: "
                            f"{', '.join(self._fields) or 'none'})")
        for name, make in self._fields.items():
            setattr(self, name, values[name] if name in values else make())

    def get_fields_and_field_types(self) -> dict[str, str]:
        return {name: type(make()).__name__ for name, make in self._fields.items()}

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and all(getattr(self, f) == getattr(other, f) for f in self._fields)

    __hash__ = None  # type: ignore[assignment]  # mutable, as rosidl's

    def __repr__(self) -> str:
        fields = ", ".join(f"{name}={getattr(self, name)!r}" for name in self._fields)
        return f"{self._package}.msg.{type(self).__name__}({fields})"

    _package = ""


def message(package: str, name: str, **fields: Callable[[], Any]) -> type[Message]:
    """A message type ``package/msg/name`` with ``fields`` (name -> what makes its default)."""
    return type(name, (Message,), {"_fields": dict(fields), "_package": package, "__doc__": f"{package}/msg/{name}",
                                   "__module__": f"{package}.msg"})


def _list() -> list[Any]:
    return []


Time = message("builtin_interfaces", "Time", sec=int, nanosec=int)
Duration = message("builtin_interfaces", "Duration", sec=int, nanosec=int)
Header = message("std_msgs", "Header", stamp=Time, frame_id=str)
_DATA = {"Bool": bool, "String": str, **{t: int for t in ("Int8", "Int16", "Int32", "Int64", "UInt8", "UInt16",
                                                          "UInt32", "UInt64", "Byte", "Char")},
         "Float32": float, "Float64": float}
STD = {name: message("std_msgs", name, data=make) for name, make in _DATA.items()}
STD.update(Header=Header, Empty=message("std_msgs", "Empty"),
           ColorRGBA=message("std_msgs", "ColorRGBA", r=float, g=float, b=float, a=float))

Point = message("geometry_msgs", "Point", x=float, y=float, z=float)
Vector3 = message("geometry_msgs", "Vector3", x=float, y=float, z=float)
Quaternion = message("geometry_msgs", "Quaternion", x=float, y=float, z=float, w=lambda: 1.0)
Pose = message("geometry_msgs", "Pose", position=Point, orientation=Quaternion)
PoseStamped = message("geometry_msgs", "PoseStamped", header=Header, pose=Pose)
Twist = message("geometry_msgs", "Twist", linear=Vector3, angular=Vector3)
Transform = message("geometry_msgs", "Transform", translation=Vector3, rotation=Quaternion)
GEOMETRY = {t.__name__: t for t in (Point, Vector3, Quaternion, Pose, PoseStamped, Twist, Transform)}
GEOMETRY.update(
    Point32=message("geometry_msgs", "Point32", x=float, y=float, z=float),
    PointStamped=message("geometry_msgs", "PointStamped", header=Header, point=Point),
    Vector3Stamped=message("geometry_msgs", "Vector3Stamped", header=Header, vector=Vector3),
    QuaternionStamped=message("geometry_msgs", "QuaternionStamped", header=Header, quaternion=Quaternion),
    TwistStamped=message("geometry_msgs", "TwistStamped", header=Header, twist=Twist),
    Accel=message("geometry_msgs", "Accel", linear=Vector3, angular=Vector3),
    Pose2D=message("geometry_msgs", "Pose2D", x=float, y=float, theta=float),
    PoseArray=message("geometry_msgs", "PoseArray", header=Header, poses=_list),
    TransformStamped=message("geometry_msgs", "TransformStamped", header=Header, child_frame_id=str,
                             transform=Transform),
)
NavSatStatus = message("sensor_msgs", "NavSatStatus", status=int, service=int)
NavSatFix = message("sensor_msgs", "NavSatFix", header=Header, status=NavSatStatus, latitude=float, longitude=float,
                    altitude=float, position_covariance=lambda: [0.0] * 9, position_covariance_type=int)
for _constant, _value in (("STATUS_NO_FIX", -1), ("STATUS_FIX", 0), ("STATUS_SBAS_FIX", 1), ("STATUS_GBAS_FIX", 2),
                          ("SERVICE_GPS", 1), ("SERVICE_GLONASS", 2), ("SERVICE_COMPASS", 4),
                          ("SERVICE_GALILEO", 8)):
    setattr(NavSatStatus, _constant, _value)
for _constant, _value in (("COVARIANCE_TYPE_UNKNOWN", 0), ("COVARIANCE_TYPE_APPROXIMATED", 1),
                          ("COVARIANCE_TYPE_DIAGONAL_KNOWN", 2), ("COVARIANCE_TYPE_KNOWN", 3)):
    setattr(NavSatFix, _constant, _value)
Path = message("nav_msgs", "Path", header=Header, poses=_list)
GeoPoint = message("geographic_msgs", "GeoPoint", latitude=float, longitude=float, altitude=float)
GeoPose = message("geographic_msgs", "GeoPose", position=GeoPoint, orientation=Quaternion)
GeoPoseStamped = message("geographic_msgs", "GeoPoseStamped", header=Header, pose=GeoPose)
GeoPath = message("geographic_msgs", "GeoPath", header=Header, poses=_list)
GEOGRAPHIC = {t.__name__: t for t in (GeoPoint, GeoPose, GeoPoseStamped, GeoPath)}
GEOGRAPHIC["GeoPointStamped"] = message("geographic_msgs", "GeoPointStamped", header=Header, position=GeoPoint)
PoseWithID = message("as2_msgs", "PoseWithID", id=str, pose=Pose)
PoseWithIDArray = message("as2_msgs", "PoseWithIDArray", header=Header, poses=_list)
#: as2_msgs/msg/TrajectoryWaypoints.msg: a path of PoseStamped with its yaw mode and speed, and the yaw modes
#: python_interface's follow_path took before 2022-12-14 (its goal's trajectory_waypoints; YawMode's since)
TrajectoryWaypoints = message("as2_msgs", "TrajectoryWaypoints", header=Header, yaw_mode=int, max_speed=float,
                              poses=_list)
TrajectoryWaypoints.KEEP_YAW, TrajectoryWaypoints.PATH_FACING = 0, 1  # type: ignore[attr-defined]
TrajectoryWaypoints.GENERATE_YAW_TRAJ, TrajectoryWaypoints.YAW_FROM_TOPIC = 2, 3  # type: ignore[attr-defined]

#: The message types by the module a mission imports them from.
MESSAGES: dict[str, dict[str, type[Message]]] = {
    "builtin_interfaces.msg": {"Time": Time, "Duration": Duration},
    "std_msgs.msg": STD,
    "geometry_msgs.msg": GEOMETRY,
    "nav_msgs.msg": {"Path": Path},
    "sensor_msgs.msg": {"NavSatFix": NavSatFix, "NavSatStatus": NavSatStatus},
    "geographic_msgs.msg": GEOGRAPHIC,
}


def point(value: Any) -> Any:
    """``(x, y, z)`` of a Point, Vector3, Pose, PoseStamped, PointStamped or PoseWithID (``(latitude, longitude,
    altitude)`` of a GeoPoint, GeoPose, GeoPoseStamped); ``value`` itself when it is none of these."""
    for attribute in ("pose", "point", "position", "vector", "translation"):
        inner = getattr(value, attribute, None) if isinstance(value, Message) else None
        if inner is not None:
            return point(inner)
    if isinstance(value, Message) and all(hasattr(value, a) for a in ("x", "y", "z")):
        return value.x, value.y, value.z
    if isinstance(value, GeoPoint):
        return value.latitude, value.longitude, value.altitude
    return value


def points(value: Any) -> Any:
    """The points of a Path, GeoPath, PoseArray, PoseWithIDArray, or of a list of poses (each :func:`point`); ``value``
    itself when it is none of these."""
    if isinstance(value, Message) and hasattr(value, "poses"):
        value = value.poses
    if isinstance(value, list | tuple) and any(isinstance(v, Message) for v in value):
        return [point(v) for v in value]
    return value


__all__ = ["MESSAGES", "Message", "NavSatFix", "Path", "Point", "Pose", "PoseStamped", "PoseWithID",
           "PoseWithIDArray", "TrajectoryWaypoints", "message", "point", "points"]
