"""The ROS 2 message types a recording writes, and their definitions as rosbag2 stores them in an MCAP file.

Each type's fields are those of its ``.msg`` file in ROS 2 Jazzy (comments left out; constants and defaults kept).
:func:`message_definition` assembles a type's complete definition in the ``ros2msg`` encoding exactly as rosbag2's
``LocalMessageDefinitionSource`` does: the type's own text first, then each type it depends on (the field types,
taken in sorted order, depth first, each once) after a delimiter line of 80 ``=`` and ``MSG: package/Type``, so
any reader that decodes rosbag2's recordings (mcap's ROS 2 support, rosbags, Foxglove, ``ros2 bag``) decodes these.
"""

from __future__ import annotations

import re

#: type name (``package/msg/Type``) -> its ``.msg`` text
DEFINITIONS: dict[str, str] = {
    "builtin_interfaces/msg/Time": "int32 sec\nuint32 nanosec\n",
    "std_msgs/msg/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "geometry_msgs/msg/Point": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/msg/Vector3": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/msg/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    "geometry_msgs/msg/Pose": "Point position\nQuaternion orientation\n",
    "geometry_msgs/msg/PoseStamped": "std_msgs/Header header\nPose pose\n",
    "geometry_msgs/msg/Twist": "Vector3 linear\nVector3 angular\n",
    "geometry_msgs/msg/TwistStamped": "std_msgs/Header header\nTwist twist\n",
    "geometry_msgs/msg/Transform": "Vector3 translation\nQuaternion rotation\n",
    "geometry_msgs/msg/TransformStamped": "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n",
    "nav_msgs/msg/Path": "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
    "sensor_msgs/msg/NavSatStatus": (
        "int8 STATUS_UNKNOWN = -2\nint8 STATUS_NO_FIX = -1\nint8 STATUS_FIX = 0\nint8 STATUS_SBAS_FIX = 1\n"
        "int8 STATUS_GBAS_FIX = 2\n\nint8 status\n\n"
        "uint16 SERVICE_UNKNOWN = 0\nuint16 SERVICE_GPS = 1\nuint16 SERVICE_GLONASS = 2\nuint16 SERVICE_COMPASS = 4\n"
        "uint16 SERVICE_GALILEO = 8\n\nuint16 service\n"),
    "sensor_msgs/msg/NavSatFix": (
        "std_msgs/Header header\n\nNavSatStatus status\n\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\n\n"
        "float64[9] position_covariance\n\nuint8 COVARIANCE_TYPE_UNKNOWN = 0\nuint8 COVARIANCE_TYPE_APPROXIMATED = 1\n"
        "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\nuint8 COVARIANCE_TYPE_KNOWN = 3\n\n"
        "uint8 position_covariance_type\n"),
    "sensor_msgs/msg/BatteryState": (
        "uint8 POWER_SUPPLY_STATUS_UNKNOWN = 0\nuint8 POWER_SUPPLY_STATUS_CHARGING = 1\n"
        "uint8 POWER_SUPPLY_STATUS_DISCHARGING = 2\nuint8 POWER_SUPPLY_STATUS_NOT_CHARGING = 3\n"
        "uint8 POWER_SUPPLY_STATUS_FULL = 4\n\n"
        "uint8 POWER_SUPPLY_HEALTH_UNKNOWN = 0\nuint8 POWER_SUPPLY_HEALTH_GOOD = 1\n"
        "uint8 POWER_SUPPLY_HEALTH_OVERHEAT = 2\nuint8 POWER_SUPPLY_HEALTH_DEAD = 3\n"
        "uint8 POWER_SUPPLY_HEALTH_OVERVOLTAGE = 4\nuint8 POWER_SUPPLY_HEALTH_UNSPEC_FAILURE = 5\n"
        "uint8 POWER_SUPPLY_HEALTH_COLD = 6\nuint8 POWER_SUPPLY_HEALTH_WATCHDOG_TIMER_EXPIRE = 7\n"
        "uint8 POWER_SUPPLY_HEALTH_SAFETY_TIMER_EXPIRE = 8\n\n"
        "uint8 POWER_SUPPLY_TECHNOLOGY_UNKNOWN = 0\nuint8 POWER_SUPPLY_TECHNOLOGY_NIMH = 1\n"
        "uint8 POWER_SUPPLY_TECHNOLOGY_LION = 2\nuint8 POWER_SUPPLY_TECHNOLOGY_LIPO = 3\n"
        "uint8 POWER_SUPPLY_TECHNOLOGY_LIFE = 4\nuint8 POWER_SUPPLY_TECHNOLOGY_NICD = 5\n"
        "uint8 POWER_SUPPLY_TECHNOLOGY_LIMN = 6\nuint8 POWER_SUPPLY_TECHNOLOGY_TERNARY = 7\n"
        "uint8 POWER_SUPPLY_TECHNOLOGY_VRLA = 8\n\n"
        "std_msgs/Header header\nfloat32 voltage\nfloat32 temperature\nfloat32 current\nfloat32 charge\n"
        "float32 capacity\nfloat32 design_capacity\nfloat32 percentage\nuint8 power_supply_status\n"
        "uint8 power_supply_health\nuint8 power_supply_technology\nbool present\n\nfloat32[] cell_voltage\n"
        "float32[] cell_temperature\n\nstring location\nstring serial_number\n"),
}

DELIMITER = "=" * 80 + "\n"
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
              "int64", "uint64", "string"}
_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")  # rosbag2's MSG_FIELD_TYPE_REGEX


def dependencies(text: str, package: str) -> list[str]:
    """The types a ``.msg`` text names (``package/Type``, as written or in ``package``), sorted, each once."""
    found = set()
    for match in _FIELD_TYPE.finditer(text):
        name = match.group(1)
        if name not in PRIMITIVES:
            found.add(name if "/" in name else f"{package}/{name}")
    return sorted(found)


def _full_name(name: str) -> str:
    package, _, type_name = name.rpartition("/")
    return name if package.count("/") else f"{package}/msg/{type_name}"


def message_definition(type_name: str) -> str:
    """The complete ``ros2msg`` definition of ``type_name`` (``package/msg/Type``), as rosbag2 writes it."""
    seen: set[str] = set()

    def text_of(name: str) -> str:
        full = _full_name(name)
        text = DEFINITIONS[full]
        for dependency in dependencies(text, full.split("/", 1)[0]):
            if dependency not in seen:
                seen.add(dependency)
                text += "\n" + DELIMITER + f"MSG: {dependency}\n" + text_of(dependency)
        return text

    return text_of(type_name)


__all__ = ["DEFINITIONS", "message_definition"]
