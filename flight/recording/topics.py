"""The topics of a recording, written once: which records of the event log each carries, as which message.

Every drone's topics are under its name (``/drone/pose`` for a single run, ``/scout/pose``, ``/carrier/pose`` for
a fleet's drones, all in one file), and ``/tf`` holds every drone's frame in the world's. The world's frame
(``world``) is the drone interface's: x east, y north, z up, in meters from the world's home; a drone's frame is
its name. Each record of a run's event log goes to at most one topic, so the counts add up to the log's:

- a ``state`` sample: ``pose``, ``velocity``, ``battery``, a transform on ``/tf`` and, when the run's world has a
  geodetic home, ``fix`` (ROS 2 types, CDR);
- ``belief_added``/``belief_removed``: ``beliefs``; ``node_status``: ``tree``; ``safety_*``: ``safety``; the
  operator's commands and the changes of the mission: ``operator_commands``; activations and how they ended:
  ``behavior_events``; every other engine event: ``events`` (the log's own record, JSON with a JSON schema);
- the mission's planned route (its literal destinations, from home): ``route`` (``nav_msgs/msg/Path``), once.

The log's first and last records (``log_started``, ``log_resumed``, ``log_closed``) are the file's metadata.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from aeroexec.drones.geodesy import enu_to_geodetic
from aeroexec.engine.events import Outcome

WORLD_FRAME = "world"
#: Records that are the file's metadata, not messages.
META_KINDS = frozenset({"log_started", "log_resumed", "log_closed"})
BEHAVIOR_KINDS = frozenset({"activated", "failed_preconditions", "rejected", *(o.value for o in Outcome)})
OPERATOR_KINDS = frozenset({"operator_command", "operator_interrupt", "mission_change"})
NAN = float("nan")


@dataclass(frozen=True)
class Drone:
    """A drone of the recording: its name (the namespace of its topics and its frame), the world's geodetic home
    (latitude, longitude, altitude AMSL) when the run has one, and the run's start (ns) its records' times add to."""

    name: str
    home: tuple[float, float, float] | None = None
    start_ns: int = 0


@dataclass(frozen=True)
class Topic:
    """One topic of the table: its name (``{drone}`` replaced by the drone's name), its schema (a ROS 2 type for
    ``cdr``, a JSON schema's name for ``json``), the records it carries (by kind) and the message it makes of one
    (a dict for CDR, the record itself for JSON; None when the record has nothing for it)."""

    name: str
    schema: str
    encoding: str
    kinds: Callable[[str], bool]
    message: Callable[[dict[str, Any], Drone, int], Any]
    what: str
    has: Callable[[Drone], bool] = lambda drone: True  # whether a drone has this topic at all


    def topic(self, drone: Drone) -> str:
        return self.name.format(drone=drone.name)


def stamp(ns: int) -> dict[str, int]:
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def header(ns: int, frame: str = WORLD_FRAME) -> dict[str, Any]:
    return {"stamp": stamp(ns), "frame_id": frame}


def _vector(values: Any) -> dict[str, float]:
    x, y, z = (float(v) for v in values)
    return {"x": x, "y": y, "z": z}


def _yaw(record: dict[str, Any]) -> dict[str, float]:
    """The drone's heading as a quaternion about z (yaw 0 = east, counterclockwise: ROS's ENU convention)."""
    half = math.radians(float(record.get("yaw") or 0.0)) / 2
    return {"x": 0.0, "y": 0.0, "z": math.sin(half), "w": math.cos(half)}


def pose(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any]:
    return {"header": header(ns), "pose": {"position": _vector(record["position"]), "orientation": _yaw(record)}}


def velocity(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any]:
    return {"header": header(ns), "twist": {"linear": _vector(record["velocity"]),
                                            "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}}


def fix(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any] | None:
    """The drone's place on the globe: its ENU position from the world's home (altitude: the home's plus its
    height, as the log's home gives it)."""
    if drone.home is None:
        return None
    lat, lon, alt = enu_to_geodetic(tuple(float(v) for v in record["position"]), drone.home)
    return {"header": header(ns, drone.name), "status": {"status": 0, "service": 0},  # STATUS_FIX, unknown service
            "latitude": lat, "longitude": lon, "altitude": alt, "position_covariance": [0.0] * 9,
            "position_covariance_type": 0}


def battery(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any]:
    """The charge left (``percentage`` 0..1); what the log does not know is NaN, as ROS says."""
    return {"header": header(ns, drone.name), "voltage": NAN, "temperature": NAN, "current": NAN, "charge": NAN,
            "capacity": NAN, "design_capacity": NAN, "percentage": float(record["battery"]) / 100.0,
            "power_supply_status": 2, "power_supply_health": 0, "power_supply_technology": 0,  # discharging
            "present": True, "cell_voltage": [], "cell_temperature": [], "location": "", "serial_number": ""}


def transform(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any]:
    return {"transforms": [{"header": header(ns), "child_frame_id": drone.name,
                            "transform": {"translation": _vector(record["position"]), "rotation": _yaw(record)}}]}


def route(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any]:
    """The planned route (a ``route`` record: ``points``, ENU) as a path of poses in the world's frame."""
    level = {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
    return {"header": header(ns), "poses": [{"header": header(ns), "pose": {"position": _vector(p),
                                                                           "orientation": level}}
                                            for p in record["points"]]}


def same(record: dict[str, Any], drone: Drone, ns: int) -> dict[str, Any]:
    return record


def _is(*kinds: str) -> Callable[[str], bool]:
    wanted = frozenset(kinds)
    return wanted.__contains__


def _other_event(kind: str) -> bool:
    return not (kind in META_KINDS or kind in BEHAVIOR_KINDS or kind in OPERATOR_KINDS or kind.startswith("safety_")
                or kind in ("state", "route", "belief_added", "belief_removed", "node_status"))


#: The table: every topic a recording has, in the order they are registered.
TOPICS: tuple[Topic, ...] = (
    Topic("/{drone}/pose", "geometry_msgs/msg/PoseStamped", "cdr", _is("state"), pose,
          "position (ENU, m) and heading"),
    Topic("/{drone}/velocity", "geometry_msgs/msg/TwistStamped", "cdr", _is("state"), velocity, "velocity (ENU, m/s)"),
    Topic("/{drone}/fix", "sensor_msgs/msg/NavSatFix", "cdr", _is("state"), fix,
          "latitude, longitude, altitude (when the world has a geodetic home)", lambda drone: drone.home is not None),
    Topic("/{drone}/battery", "sensor_msgs/msg/BatteryState", "cdr", _is("state"), battery, "charge left"),
    Topic("/tf", "tf2_msgs/msg/TFMessage", "cdr", _is("state"), transform, "world -> drone"),
    Topic("/{drone}/route", "nav_msgs/msg/Path", "cdr", _is("route"), route, "the mission's planned route"),
    Topic("/{drone}/behavior_events", "aeroexec.BehaviorEvent", "json", BEHAVIOR_KINDS.__contains__, same,
          "activations and how they ended"),
    Topic("/{drone}/beliefs", "aeroexec.BeliefChange", "json", _is("belief_added", "belief_removed"), same,
          "beliefs added and removed"),
    Topic("/{drone}/operator_commands", "aeroexec.OperatorCommand", "json", OPERATOR_KINDS.__contains__, same,
          "the operator's commands, mission changes"),
    Topic("/{drone}/tree", "aeroexec.NodeStatus", "json", _is("node_status"), same, "tree node statuses"),
    Topic("/{drone}/safety", "aeroexec.SafetyEvent", "json", lambda kind: kind.startswith("safety_"), same,
          "safety rules watched, violated, met, restored"),
    Topic("/{drone}/events", "aeroexec.EngineEvent", "json", _other_event, same, "every other engine event"),
)


def topics_of(kind: str) -> list[Topic]:
    """The topics a record of ``kind`` goes to."""
    found = _BY_KIND.get(kind)
    if found is None:
        found = _BY_KIND[kind] = [t for t in TOPICS if t.kinds(kind)]
    return found


_BY_KIND: dict[str, list[Topic]] = {}

_EVENT = {"time": {"type": "number", "description": "engine seconds"}, "kind": {"type": "string"},
          "behavior": {"type": "string"}, "detail": {"type": "string"}, "reason": {"type": "string"},
          "arguments": {"type": "object"}, "result": {}, "data": {"type": "object"}}

#: The JSON schemas of the ``json`` topics, by name.
JSON_SCHEMAS: dict[str, dict[str, Any]] = {
    "aeroexec.BehaviorEvent": {"title": "a behavior activated, refused or ended (the event log's record)",
                               "type": "object", "properties": _EVENT, "required": ["time", "kind", "behavior"]},
    "aeroexec.BeliefChange": {"title": "a belief added or removed (the event log's record)", "type": "object",
                              "properties": {"time": {"type": "number"},
                                             "kind": {"enum": ["belief_added", "belief_removed"]},
                                             "belief": {"type": "string"}, "reason": {"type": "string"}},
                              "required": ["time", "kind", "belief"]},
    "aeroexec.OperatorCommand": {"title": "an operator's command or a change of the mission (the event log's record)",
                                 "type": "object", "properties": _EVENT, "required": ["time", "kind"]},
    "aeroexec.NodeStatus": {"title": "a tree node's status change (the event log's record)", "type": "object",
                            "properties": {**_EVENT, "data": {"type": "object", "properties": {
                                "node": {"type": "string"}, "old": {"type": "string"}, "new": {"type": "string"},
                                "type": {"type": "string"}, "line": {"type": "integer"},
                                "depth": {"type": "integer"}, "uid": {"type": "integer"}}}},
                            "required": ["time", "kind"]},
    "aeroexec.SafetyEvent": {"title": "a safety rule's state (the event log's record)", "type": "object",
                             "properties": _EVENT, "required": ["time", "kind"]},
    "aeroexec.EngineEvent": {"title": "an engine event (the event log's record)", "type": "object",
                             "properties": _EVENT, "required": ["time", "kind"]},
}

__all__ = ["JSON_SCHEMAS", "TOPICS", "WORLD_FRAME", "Drone", "Topic", "topics_of"]
