"""Aerostack2's behavior-tree nodes (``as2_behavior_tree``) read as the catalog's behaviors and belief checks.

A BehaviorTree.CPP file that uses Aerostack2's nodes is mapped when it is loaded, node by node; nothing of it
needs a node class of its own at run time. Aerostack2 writes BehaviorTree.CPP 3's XML, so its spellings are
read too (``SequenceStar``, ``Parallel success_threshold/failure_threshold``, ``SubTree __shared_blackboard``).

==============================================  =====================================================
Aerostack2 node                                 here
==============================================  =====================================================
``TakeOff height speed``                        ``TAKE_OFF ALTITUDE=height`` (the climb speed is the vehicle's)
``Land speed``                                  ``LAND`` (the descent speed is the vehicle's)
``GoTo pose="x;y;z" max_speed yaw_mode          ``GO_TO_POINT COORDINATES SPEED``; yaw_mode 2 (FIXED_YAW) ends
yaw_angle frame_id``                            facing yaw_angle (radians), 0 and 1 face the travel
``FollowPath path="x;y;z|x;y;z" speed``         ``FOLLOW_PATH PATH SPEED``
``FollowReference reference max_speed_x..``     ``GO_TO_POINT COORDINATES=reference SPEED``
``GoToGps latitude longitude altitude``         ``GO_TO_POINT`` at the point's ENU coordinates from home
``Arm``, ``Offboard``                           succeed (TAKE_OFF arms the drone and chooses its mode)
``Disarm``                                      ``CheckBelief flight_state(self, landed)``
``IsFlying``                                    ``CheckBelief flight_state(self, ?s), belong(?s, [hovering, moving])``
``Echo data``                                   ``NOTIFY_OPERATOR MESSAGE=data``
``SendEvent topic_name data``                   ``AddBelief event(topic, data)``
``WaitForEvent topic_name result`` (decorator)  waits for a belief ``event(topic, ?result)``, then ticks its child
``WaitForAlert topic_name alert`` (decorator)   waits for a belief ``alert(topic, ?alert)``, then ticks its child
``SetOrigin latitude longitude``                succeeds when the origin is the home point (the earth frame's)
``GetOrigin latitude longitude altitude``       writes the home point's
``GpsToCartesian latitude longitude z out_pose``  writes the point's ``x;y;z`` from home
==============================================  =====================================================

Events and alerts are beliefs: the operator sends one with ``aeroexec ctl add "event(start, go)"``. Ports that
name a ROS 2 topic, service or action server are refused (``FollowPath path_topic_name``), and so is any other
node of the file bound to one (this mission uses ROS 2 beyond the drone interface).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

from aeroexec.dialects.aerostack2.behaviors import EARTH_FRAMES, FIXED_YAW, degrees
from aeroexec.dialects.aerostack2.node_ports import PORTS, is_aerostack2
from aeroexec.dialects.ros import ROS2_BEYOND
from aeroexec.drones.geodesy import Geodetic, geodetic_to_enu
from aeroexec.engine.yaml_nodes import suggestion
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode
from aeroexec.trees.ports import bare_key, parse_number
from aeroexec.trees.runtime.kinds import kind_of

#: Ports every Aerostack2 action has for the ROS 2 server behind it: ignored here.
SERVER_PORTS = ("server_name", "server_timeout", "service_name")
#: BehaviorTree.CPP 3's names Aerostack2's files use, and their names in version 4.
V3_TYPES = {"SequenceStar": "SequenceWithMemory"}
V3_PORTS = {"success_threshold": "success_count", "failure_threshold": "failure_count",
            "__shared_blackboard": "_autoremap"}
_ROS_PORT_ENDINGS = ("topic_name", "topic", "service_name", "server_name", "action_name")
#: What a mapped document was written for (``verify --strict-btcpp`` says it is not BehaviorTree.CPP 4's).
DIALECT = "BehaviorTree.CPP 3 with Aerostack2's nodes (as2_behavior_tree)"
#: How far (meters) an origin may be from the home point and still be it.
ORIGIN_TOLERANCE = 1.0


def aerostack2_tree(document: TreeDocument, home: Geodetic | None = None) -> TreeDocument:
    """The document with Aerostack2's nodes mapped (itself when it has none); ``home`` places GPS points.
    Every node that cannot be mapped is a problem of one :class:`TreeFormatError`."""
    if not is_aerostack2(document):
        return document
    mapper = _Mapper(document, tuple(home) if home is not None else None)
    trees = {tree_id: mapper.node(root) for tree_id, root in document.trees.items()}
    if mapper.problems:
        raise TreeFormatError(mapper.problems)
    dialect = (document.file, document.lines.get(document.main, 0),
               f"written for {DIALECT}: BehaviorTree.CPP 4 reads what aeroexec makes of it (aeroexec convert)")
    return replace(document, trees=trees, not_portable=[dialect, *document.not_portable])


class _Mapper:
    def __init__(self, document: TreeDocument, home: tuple[float, ...] | None) -> None:
        self.home = home
        self.problems: list[tuple[str, int, str]] = []
        self.origin_keys = self._origin_keys(document)

    def problem(self, node: TreeNode, message: str) -> None:
        self.problems.append((node.file, node.line, message))

    @staticmethod
    def _origin_keys(document: TreeDocument) -> dict[str, int]:
        """Blackboard keys only GetOrigin writes -> which of its values (0 latitude, 1 longitude, 2 altitude)."""
        writers: dict[str, list[tuple[str, int]]] = {}
        for root in document.trees.values():
            for node in root.walk():
                for index, port in enumerate(("latitude", "longitude", "altitude")):
                    key = bare_key(node.ports.get(port, ""))
                    if key is not None and node.type == "GetOrigin":
                        writers.setdefault(key, []).append(("GetOrigin", index))
                for text in node.ports.values():
                    key = bare_key(text)
                    if key is not None and node.type not in ("GetOrigin", "GpsToCartesian", "GoToGps", "SetOrigin"):
                        writers.setdefault(key, []).append((node.type, -1))
        return {key: found[0][1] for key, found in writers.items()
                if all(w == found[0] for w in found) and found[0][0] == "GetOrigin"}

    # -- nodes -------------------------------------------------------------------------------------------
    def node(self, node: TreeNode) -> TreeNode:
        children = [self.node(child) for child in node.children]
        mapper = _NODES.get(node.type)
        if mapper is not None:
            unknown = [p for p in node.ports if p not in PORTS[node.type] and p not in SERVER_PORTS
                       and p != "name" and not p.startswith("_")]
            for port in unknown:
                self.problem(node, f"The port {port} of node {node.type} does not exist (Aerostack2's {node.type} "
                                   f"takes {', '.join(PORTS[node.type]) or 'no ports'})"
                                   f"{suggestion(port, PORTS[node.type])}")
            return mapper(self, node, children)
        ports = {V3_PORTS.get(k, k): v for k, v in node.ports.items()}
        if kind_of(node.type) is None:
            bound = next((p for p in node.ports if p.endswith(_ROS_PORT_ENDINGS)), None)
            if bound is not None:
                self.problem(node, f"The node {node.type} is bound to the ROS 2 {_what(bound)} "
                                   f"{node.ports[bound]!r} ({ROS2_BEYOND})")
        return replace(node, type=V3_TYPES.get(node.type, node.type), ports=ports, children=children)

    def _leaf(self, node: TreeNode, kind: str, ports: dict[str, str] | None = None,
              children: list[TreeNode] | None = None) -> TreeNode:
        return replace(node, type=kind, ports=ports or {}, children=children or [])

    def _frame(self, node: TreeNode) -> None:
        frame = node.ports.get("frame_id", "").strip()
        if frame and frame not in EARTH_FRAMES and bare_key(frame) is None:
            self.problem(node, f"The frame {frame!r} of {node.type} is not correct: aeroexec flies in the earth frame "
                               f"(local ENU from home); frames of ROS 2's tf tree are not available ({ROS2_BEYOND})")

    def _yaw(self, node: TreeNode) -> dict[str, str]:
        mode, angle = parse_number(node.ports.get("yaw_mode", "")), parse_number(node.ports.get("yaw_angle", "0"))
        if mode == FIXED_YAW and angle is not None:
            return {"YAW_ANGLE_AT_THE_END": _number(degrees(angle))}
        if mode is not None and mode > FIXED_YAW:
            self.problem(node, f"The yaw mode {mode} of {node.type} is not supported: KEEP_YAW (0), PATH_FACING (1) "
                               f"and FIXED_YAW (2) are (modes 3 to 6 follow ROS 2 topics and frames)")
        return {}

    def _speed(self, node: TreeNode, *ports: str) -> dict[str, str]:
        given = [node.ports[p] for p in ports if node.ports.get(p, "").strip()]
        if len(given) > 1:
            numbers = [parse_number(g) for g in given]
            if all(n is not None for n in numbers):
                positive = [n for n in numbers if n > 0]
                return {"SPEED": _number(max(positive))} if positive else {}
        return {"SPEED": given[0]} if given else {}

    def go_to(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        self._frame(node)
        return self._leaf(node, "GO_TO_POINT", {"COORDINATES": node.ports.get("pose", ""),
                                                **self._speed(node, "max_speed"), **self._yaw(node)})

    def follow_reference(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        self._frame(node)
        return self._leaf(node, "GO_TO_POINT", {"COORDINATES": node.ports.get("reference", ""), **self._yaw(node),
                                                **self._speed(node, "max_speed_x", "max_speed_y", "max_speed_z")})

    def follow_path(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        self._frame(node)
        if node.ports.get("path_topic_name", "").strip():
            self.problem(node, f"FollowPath takes its path from the ROS 2 topic {node.ports['path_topic_name']!r} "
                               f"({ROS2_BEYOND}): give path=\"x;y;z|x;y;z\"")
        text = node.ports.get("path", "")
        path = text if bare_key(text) is not None or "|" not in text else \
            "[" + ", ".join(f"[{p.replace(';', ', ')}]" for p in text.split("|") if p.strip()) + "]"
        return self._leaf(node, "FOLLOW_PATH", {"PATH": path, **self._speed(node, "speed")})

    def go_to_gps(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        point = self._place(node, "latitude", "longitude", node.ports.get("altitude", ""))
        return self._leaf(node, "GO_TO_POINT", {"COORDINATES": point, **self._speed(node, "max_speed"),
                                                **self._yaw(node)})

    def gps_to_cartesian(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        point = self._place(node, "latitude", "longitude", node.ports.get("z", "")).replace(", ", ";")
        key = bare_key(node.ports.get("out_pose", ""))
        if key is None:
            self.problem(node, "GpsToCartesian needs out_pose=\"{key}\", where the point is written")
            return self._leaf(node, "AlwaysFailure")
        return self._leaf(node, "SetBlackboard", {"output_key": key, "value": point})

    def _gps(self, node: TreeNode, port: str) -> float | None:
        text = node.ports.get(port, "")
        key = bare_key(text)
        if key is not None and key in self.origin_keys and self.home is not None:
            return self.home[self.origin_keys[key]]
        number = parse_number(text)
        if number is None:
            self.problem(node, f"The {port} {text!r} of {node.type} is not correct: a number in degrees, or a key "
                               f"only GetOrigin writes, is expected (GPS points are placed before flight)")
        return number

    def _place(self, node: TreeNode, latitude: str, longitude: str, height: str) -> str:
        """``"east, north, height"`` of a GPS point from home (its height is meters above the origin)."""
        lat, lon = self._gps(node, latitude), self._gps(node, longitude)
        if lat is None or lon is None:
            return height
        if self.home is None:
            self.problem(node, f"{node.type} takes a GPS point, and there is no home point to place it from "
                               f"(give a world, or --home LAT,LON)")
            return height
        east, north, _ = geodetic_to_enu((lat, lon, self.home[2]), self.home)
        return f"{_number(round(east, 3))}, {_number(round(north, 3))}, {height.strip() or 0}"

    def set_origin(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        lat, lon = self._gps(node, "latitude"), self._gps(node, "longitude")
        if lat is not None and lon is not None and self.home is not None:
            east, north, _ = geodetic_to_enu((lat, lon, self.home[2]), self.home)
            if math.hypot(east, north) > ORIGIN_TOLERANCE:
                self.problem(node, f"SetOrigin ({lat}, {lon}) is {math.hypot(east, north):.0f} m from the home point "
                                   f"({self.home[0]}, {self.home[1]}): the earth frame is fixed at home (fly with "
                                   f"--home at this origin, or a world whose home it is)")
        elif self.home is None:
            self.problem(node, "SetOrigin needs the home point to compare with (give a world, or --home LAT,LON)")
        return self._leaf(node, "AlwaysSuccess")

    def get_origin(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        if self.home is None:
            self.problem(node, "GetOrigin needs the home point (give a world, or --home LAT,LON)")
            return self._leaf(node, "AlwaysFailure")
        writes = [TreeNode("SetBlackboard", f"{node.name}/{port}", {"output_key": bare_key(node.ports[port]) or
                                                                    node.ports[port].strip(),
                                                                    "value": _number(self.home[index])},
                           [], node.file, node.line, tag="SetBlackboard")
                  for index, port in enumerate(("latitude", "longitude", "altitude")) if node.ports.get(port)]
        return self._leaf(node, "SequenceWithMemory", {}, writes) if writes else self._leaf(node, "AlwaysSuccess")

    def send_event(self, node: TreeNode, children: list[TreeNode]) -> TreeNode:
        topic, data = _topic(node), node.ports.get("data", "")
        term = data.strip() if bare_key(data) is not None else _quoted(data)
        return self._leaf(node, "AddBelief", {"belief": f"event({topic}, {term})"})

    def wait(self, node: TreeNode, children: list[TreeNode], predicate: str, output: str) -> TreeNode:
        """``SequenceWithMemory[ForceSuccess[KeepRunningUntilFailure[Inverter[QueryBelief]]], child]``: RUNNING
        until the belief holds (writing its value), then the child, as Aerostack2's decorator does."""
        key = bare_key(node.ports.get(output, ""))
        variable = f"?{key}" if key is not None and _variable_name(key) else "?"
        query = TreeNode("QueryBelief", f"{node.name}/{predicate}", {"belief": f"{predicate}({_topic(node)}, "
                                                                               f"{variable})"},
                         [], node.file, node.line, tag="QueryBelief")
        wait = query
        for kind in ("Inverter", "KeepRunningUntilFailure", "ForceSuccess"):
            wait = TreeNode(kind, f"{node.name}/wait", {}, [wait], node.file, node.line, tag=kind)
        if key is not None and variable == "?":
            self.problem(node, f"The key {key!r} of {node.type} cannot hold a belief's value (a name of letters, "
                               f"digits and _ is expected)")
        return self._leaf(node, "SequenceWithMemory", {}, [wait, *children])


def _what(port: str) -> str:
    return "service" if "service" in port else "action server" if "server" in port or "action" in port else "topic"


def _topic(node: TreeNode) -> str:
    return _quoted(node.ports.get("topic_name", "").strip().lstrip("/"))


def _quoted(text: str) -> str:
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def _variable_name(key: str) -> bool:
    return key.replace("_", "a").isalnum() and key[0].isalpha()


def _number(value: float) -> str:
    return f"{value:g}" if abs(value) < 1e6 else str(value)


_Mapping = Callable[[_Mapper, TreeNode, list[TreeNode]], TreeNode]
_NODES: dict[str, _Mapping] = {
    "TakeOff": lambda m, n, c: m._leaf(n, "TAKE_OFF", {"ALTITUDE": n.ports["height"]} if "height" in n.ports else {}),
    "Land": lambda m, n, c: m._leaf(n, "LAND"),
    "GoTo": _Mapper.go_to,
    "FollowReference": _Mapper.follow_reference,
    "FollowPath": _Mapper.follow_path,
    "GoToGps": _Mapper.go_to_gps,
    "Arm": lambda m, n, c: m._leaf(n, "AlwaysSuccess"),
    "Offboard": lambda m, n, c: m._leaf(n, "AlwaysSuccess"),
    "Disarm": lambda m, n, c: m._leaf(n, "CheckBelief", {"belief": "flight_state(self, landed)"}),
    "IsFlying": lambda m, n, c: m._leaf(n, "CheckBelief", {
        "belief": "flight_state(self, ?s), belong(?s, [hovering, moving])"}),
    "Echo": lambda m, n, c: m._leaf(n, "NOTIFY_OPERATOR", {"MESSAGE": n.ports.get("data", "")}),
    "SendEvent": _Mapper.send_event,
    "WaitForEvent": lambda m, n, c: m.wait(n, c, "event", "result"),
    "WaitForAlert": lambda m, n, c: m.wait(n, c, "alert", "alert"),
    "SetOrigin": _Mapper.set_origin,
    "GetOrigin": _Mapper.get_origin,
    "GpsToCartesian": _Mapper.gps_to_cartesian,
}


__all__ = ["PORTS", "aerostack2_tree", "is_aerostack2"]
