"""``rclpy.qos`` as a mission sees it: QoS profiles and their policies as data, with rclpy's values, for the
publishers aeroexec serves (``create_publisher(String, "start", qos_profile_system_default)``). A profile given to
what needs a ROS 2 graph (a subscription, a service) is refused with that use, by name, as before."""

from __future__ import annotations

import enum
from typing import Any


class HistoryPolicy(enum.IntEnum):
    """rmw_qos_history_policy_t."""

    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2
    UNKNOWN = 3


class ReliabilityPolicy(enum.IntEnum):
    """rmw_qos_reliability_policy_t."""

    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class DurabilityPolicy(enum.IntEnum):
    """rmw_qos_durability_policy_t."""

    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class LivelinessPolicy(enum.IntEnum):
    """rmw_qos_liveliness_policy_t."""

    SYSTEM_DEFAULT = 0
    AUTOMATIC = 1
    MANUAL_BY_TOPIC = 3
    UNKNOWN = 4
    BEST_AVAILABLE = 5


# rclpy's older names of the policies
QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
QoSDurabilityPolicy = DurabilityPolicy
QoSLivelinessPolicy = LivelinessPolicy


class InvalidQoSProfileException(Exception):
    """A profile made without its history or depth, as rclpy raises."""


class QoSProfile:
    """A QoS profile, as rclpy makes one: ``history`` or ``depth`` must be given (a depth alone is KEEP_LAST)."""

    __slots__ = ("history", "depth", "reliability", "durability", "liveliness", "avoid_ros_namespace_conventions")

    def __init__(self, **kwargs: Any) -> None:
        if "history" not in kwargs and "depth" not in kwargs:
            raise InvalidQoSProfileException("Invalid QoSProfile: History and/or depth settings are required.")
        unknown = set(kwargs) - set(self.__slots__) - {"deadline", "lifespan", "liveliness_lease_duration"}
        if unknown:
            raise TypeError(f"QoSProfile got unexpected keyword arguments {sorted(unknown)}")
        self.history = HistoryPolicy(kwargs.get("history", HistoryPolicy.KEEP_LAST))
        self.depth = int(kwargs.get("depth", 0))
        self.reliability = ReliabilityPolicy(kwargs.get("reliability", ReliabilityPolicy.RELIABLE))
        self.durability = DurabilityPolicy(kwargs.get("durability", DurabilityPolicy.VOLATILE))
        self.liveliness = LivelinessPolicy(kwargs.get("liveliness", LivelinessPolicy.SYSTEM_DEFAULT))
        self.avoid_ros_namespace_conventions = bool(kwargs.get("avoid_ros_namespace_conventions", False))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, QoSProfile) and all(getattr(self, s) == getattr(other, s) for s in self.__slots__)

    __hash__ = None  # type: ignore[assignment]  # mutable, as rclpy's

    def __repr__(self) -> str:
        return (f"QoSProfile(history={self.history.name}, depth={self.depth}, reliability={self.reliability.name}, "
                f"durability={self.durability.name})")


def _profile(history: HistoryPolicy, depth: int, reliability: ReliabilityPolicy,
             durability: DurabilityPolicy) -> QoSProfile:
    return QoSProfile(history=history, depth=depth, reliability=reliability, durability=durability)


# rmw's presets (rmw/qos_profiles.h)
qos_profile_system_default = _profile(HistoryPolicy.SYSTEM_DEFAULT, 0, ReliabilityPolicy.SYSTEM_DEFAULT,
                                      DurabilityPolicy.SYSTEM_DEFAULT)
qos_profile_sensor_data = _profile(HistoryPolicy.KEEP_LAST, 5, ReliabilityPolicy.BEST_EFFORT,
                                   DurabilityPolicy.VOLATILE)
qos_profile_services_default = _profile(HistoryPolicy.KEEP_LAST, 10, ReliabilityPolicy.RELIABLE,
                                        DurabilityPolicy.VOLATILE)
qos_profile_parameters = _profile(HistoryPolicy.KEEP_LAST, 1000, ReliabilityPolicy.RELIABLE,
                                  DurabilityPolicy.VOLATILE)
qos_profile_parameter_events = _profile(HistoryPolicy.KEEP_LAST, 1000, ReliabilityPolicy.RELIABLE,
                                        DurabilityPolicy.VOLATILE)
qos_profile_action_status_default = _profile(HistoryPolicy.KEEP_LAST, 1, ReliabilityPolicy.RELIABLE,
                                             DurabilityPolicy.TRANSIENT_LOCAL)


class QoSPresetProfiles(enum.Enum):
    """The presets by name (``QoSPresetProfiles.SENSOR_DATA.value``)."""

    SYSTEM_DEFAULT = qos_profile_system_default
    SENSOR_DATA = qos_profile_sensor_data
    SERVICES_DEFAULT = qos_profile_services_default
    PARAMETERS = qos_profile_parameters
    PARAMETER_EVENTS = qos_profile_parameter_events
    ACTION_STATUS_DEFAULT = qos_profile_action_status_default

    @classmethod
    def get_from_short_key(cls, name: str) -> QoSProfile:
        return cls[name.upper()].value


__all__ = ["DurabilityPolicy", "HistoryPolicy", "InvalidQoSProfileException", "LivelinessPolicy", "QoSDurabilityPolicy",
           "QoSHistoryPolicy", "QoSLivelinessPolicy", "QoSPresetProfiles", "QoSProfile", "QoSReliabilityPolicy",
           "ReliabilityPolicy", "qos_profile_action_status_default", "qos_profile_parameter_events",
           "qos_profile_parameters", "qos_profile_sensor_data", "qos_profile_services_default",
           "qos_profile_system_default"]
