"""The ground Aerostack2's missions were written for: Gazebo's empty world (its examples' ``world.yaml``), at the
GPS origin a mission names.

An Aerostack2 script (a program importing ``as2_python_api``) or behavior tree (a BehaviorTree.CPP file using
Aerostack2's nodes) flies in open ground, as in the simulator its author used, not in aeroexec's default field
(whose walls and tower stand where Aerostack2's examples fly). Its GPS origin places that ground on Earth: the
script's ``gps.set_origin(...)`` or the tree's ``SetOrigin``, else its first GPS point (``go_to_gps_point``,
``GoToGps``, ``GpsToCartesian``; a ``DroneInterfaceGPS``'s ``go_to`` and ``follow_path``). A script whose project
keeps the simulator's world config (``sim_config/world.json``...: :mod:`~aeroexec.dialects.aerostack2.sim_world`)
flies from where that config spawns its drone, among its objects' frames. A mission that looks for ArUco markers
needs the default field's markers: it keeps that field (the dialect gives it no ground).
"""

from __future__ import annotations

import ast
from pathlib import Path

from aeroexec.dialects.aerostack2.node_ports import PORTS
from aeroexec.trees.mission_world import MissionGround

from aeroexec.limits import MAX_FILE_BYTES

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

WRITTEN_FOR = "Gazebo's empty world"
_API = ("as2_python_api", "python_interface")  # Aerostack2's Python API, and its name before 1.0
#: What a mission uses that is only in the default field (its markers).
_FIELD_WORDS = ("aruco", "marker")
_GPS_CALLS = ("go_to_gps_point", "go_to_gps_point_path_facing", "go_to_gps", "go_to_gps_path_facing",
              "follow_gps_path", "follow_path_gps")
_GPS_NODES = ("GoToGps", "GpsToCartesian")


def _gps(value: Any) -> tuple[float, float, float] | None:
    """(lat, lon, alt) of a constant GPS point (a list of 2 or 3 numbers within the Earth's ranges)."""
    if isinstance(value, tuple | list) and len(value) in (2, 3) and all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        lat, lon = float(value[0]), float(value[1])
        if -90 <= lat <= 90 and -180 <= lon <= 180 and (lat, lon) != (0.0, 0.0):
            return lat, lon, float(value[2]) if len(value) == 3 else 0.0
    return None


def _gps_interface_only(tree: ast.Module) -> bool:
    """The script's drone interfaces are all ``DroneInterfaceGPS``, whose ``go_to`` and ``follow_path`` take GPS
    points (it imports no other drone interface)."""
    names = {a.name.rsplit(".", 1)[-1] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom | ast.Import)
             for a in n.names}
    return "DroneInterfaceGPS" in names and not names & {"DroneInterface", "DroneInterfaceBase", "DroneInterfaceTeleop"}


def _script_origin(tree: ast.Module) -> tuple[float, float, float] | None:
    from aeroexec.engine.missions.constants import NOT_CONSTANT, Constants  # here: only Aerostack2's scripts

    gps_calls = _GPS_CALLS + (("go_to", "follow_path") if _gps_interface_only(tree) else ())

    constants = Constants(tree)
    firsts: dict[str, Any] = {}  # a loop's target -> the first item of what it loops over
    for node in ast.walk(tree):
        if isinstance(node, ast.For) and isinstance(node.target, ast.Name):
            items = constants.value(node.iter)
            if isinstance(items, tuple) and items:
                firsts.setdefault(node.target.id, items[0])
    set_origin, first_point = None, None
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
            continue
        arguments = [constants.value(a) for a in node.args]
        if node.args and len(node.args) >= 2 and all(isinstance(a, int | float) for a in arguments[:3]):
            point = tuple(arguments[:3])
        elif node.args:
            point = arguments[0]
            if point is NOT_CONSTANT and isinstance(node.args[0], ast.Name):
                point = firsts.get(node.args[0].id, NOT_CONSTANT)
            if node.func.attr.startswith("follow") and isinstance(point, tuple) and point:
                point = point[0]
        else:
            continue
        if node.func.attr == "set_origin" and set_origin is None:
            set_origin = _gps(point)
        elif node.func.attr in gps_calls and first_point is None:
            found = _gps(point)
            first_point = (found[0], found[1], 0.0) if found is not None else None
    return set_origin or first_point


def _script_ground(path: Path, text: str) -> MissionGround | None:
    if not any(api in text for api in _API):
        return None  # a script that never names Aerostack2's API does not import it: not parsed
    try:
        tree = ast.parse(text, str(path))
    except (SyntaxError, ValueError):
        return None
    imports = [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    imports += [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module and not n.level]
    if not any(name.split(".")[0] in _API for name in imports):
        return None
    from aeroexec.dialects.aerostack2.sim_world import project_world  # here: only Aerostack2's scripts
    from aeroexec.engine.missions.standins import script_drones

    drones = script_drones(tree)
    world = project_world(path, drones)
    if world is None:
        return MissionGround(WRITTEN_FOR, _script_origin(tree))
    try:
        config = str(world.file.relative_to(path.parent))
    except ValueError:
        config = str(world.file)
    first = drones[0] if drones else None
    return MissionGround(WRITTEN_FOR, _script_origin(tree), frames=world.frames_from(first), config=config,
                         starts=world.starts_from(first))


def _number(text: str | None) -> float | None:
    try:
        return float(text) if text is not None else None
    except ValueError:
        return None  # a blackboard entry ({lat}): known only in flight


def _tree_ground(text: str) -> MissionGround | None:
    if "&#" not in text and not any(name in text for name in PORTS):
        return None  # a file that never names one of Aerostack2's nodes (even by character references) has none
    import xml.etree.ElementTree as ElementTree  # here: only a file that may use them

    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:
        return None  # the reader says why
    nodes = [(e.get("ID") or e.tag, e) for e in root.iter() if (e.get("ID") or e.tag) in PORTS]
    if not nodes:
        return None
    origin = None
    for kind in ("SetOrigin", *_GPS_NODES):
        for name, element in nodes:
            if name == kind and origin is None:
                lat, lon = _number(element.get("latitude")), _number(element.get("longitude"))
                if lat is not None and lon is not None:
                    found = _gps((lat, lon, _number(element.get("altitude")) or 0.0))
                    origin = found if kind == "SetOrigin" or found is None else (found[0], found[1], 0.0)
    return MissionGround(WRITTEN_FOR, origin)


def mission_ground(path: Path) -> MissionGround | None:
    """The open ground of an Aerostack2 script or tree at ``path``; None for any other mission, and for one that
    looks for the default field's markers."""
    if path.suffix not in (".py", ".xml") or not path.is_file() or path.stat().st_size > MAX_FILE_BYTES:
        return None
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None  # the mission's check says why
    if any(word in text.lower() for word in _FIELD_WORDS):
        return None
    return _script_ground(path, text) if path.suffix == ".py" else _tree_ground(text)


__all__ = ["WRITTEN_FOR", "mission_ground"]
