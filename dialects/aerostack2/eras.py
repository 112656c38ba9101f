"""Aerostack2's rules of an earlier era, for the scripts written for it: a ``follow_path`` from the ground.

A script importing ``python_interface`` (Aerostack2 before 1.0: the package was renamed ``as2_python_api`` on
2022-12-20) was written for an Aerostack2 whose follow_path behavior took a path from the ground. Its
``FollowPathBehaviour`` checked only that the path was not empty (aerostack2/follow_path_behaviour, v0.2.0
88253dd, 2022-07-19), its plugin handed the path to the trajectory generator, which plans from where the drone is
and checks no platform state (aerostack2/trajectory_generator a11e3a7), and the controller and the platform sent
its commands to the vehicle whatever its flight state: with no other check (aerostack2-developers/as2_core
``AerialPlatform::sendCommand``, July 2022), then only when armed and in offboard mode (aerostack2/as2_core
6959a15, 2022-10-03; the controller's ``control_timer_callback`` the same, aerostack2 e3dc1ca2), as PX4 always
wanted. So an armed drone in offboard mode climbed along the path: its
``follow_path([[0, 0, 3]], 1)`` was its take-off (python_interface's own ``examples/ex_fp.py``, ca7ff46). The
behavior rejects a goal unless the platform is FLYING since aerostack2 96d3a3f3 (2022-12-14; in the
follow_path_behaviour repository be6f7e7, merged 10265cb on 2022-12-15).

Such a call is flown here as ``TAKE_OFF`` to the altitude of the path's first point, then the path: the climb is
straight up at the vehicle's take-off speed (the era's trajectory climbed at the path's speed along a curve to the
first point: the same place when that point is above the drone, as in every such script found, or nearly: 0.1 m).
On a drone not armed, or not in offboard mode, nothing moved then (the behavior waited for ever): the call is
refused as today. The platform's state machine stayed LANDED in such a flight: a ``land()`` after it lands here, as
0.2.0's land behavior did (aerostack2/land_behaviour fe0b6e0: the state machine's refused LAND event was only
logged), the version python_interface's ex_fp.py was written against; from 2022-11-17 (d590455) to the follow_path
check the land behavior rejected it.
``go_to`` is not given this rule: the go_to behavior rejected a goal unless FLYING from 2022-11-17
(aerostack2/goto_behaviour bd5740a), while the package was still ``python_interface``, so a script of that name
cannot tell which rule it was written for. Scripts importing ``as2_python_api`` keep the catalog's preconditions.
"""

from __future__ import annotations

import ast
from collections.abc import Mapping, Sequence
from typing import Any

from aeroexec.dialects.aerostack2.behaviors import Request

#: The name of Aerostack2's Python API in the era whose follow_path took off by its path.
ERA_API = "python_interface"
#: The modules whose calls take off by their path in that era (follow_path, and its GPS form, the same action).
BY_PATH = ("follow_path", "follow_path_gps")
RULE = ("follow_path from the ground takes off by its path, as Aerostack2 before December 2022 did (this script "
        "imports python_interface, the Python API's name until its rename as2_python_api on 2022-12-20; the "
        "follow_path behavior rejects a goal unless the drone flies since aerostack2 96d3a3f3, 2022-12-14): "
        "TAKE_OFF to the path's first altitude, then the path")
NOT_ARMED = ("follow_path from the ground took off by its path in Aerostack2 before December 2022 (this script "
             "imports python_interface) only on a drone armed and in offboard mode (arm() and offboard() first); "
             "this script never calls both, so the drone would not have moved")


def imports_era_api(nodes: Sequence[ast.AST]) -> ast.AST | None:
    """The first import of ``python_interface`` in a program (None when it has none)."""
    for node in nodes:
        if isinstance(node, ast.Import) and any(a.name.split(".")[0] == ERA_API for a in node.names):
            return node
        if isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").split(".")[0] == ERA_API:
            return node
    return None


def arms(nodes: Sequence[ast.AST]) -> bool:
    """True when a program calls ``arm()`` and ``offboard()`` (on anything: the check takes it at its word)."""
    called = {n.func.attr for n in nodes if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)}
    return {"arm", "offboard"} <= called


def take_off_by_path(module: str, requests: Sequence[Request]) -> list[Request]:
    """The requests of a call from the ground under the era's rule: TAKE_OFF to the first point's altitude, then
    the call's own (unchanged when the call is not a follow_path). A path, point or altitude not known before
    flight (the static check's) stands for the altitude, which is not known either."""
    if module not in BY_PATH or not requests or requests[0].behavior != "FOLLOW_PATH":
        return list(requests)
    path = requests[0].arguments.get("PATH")
    first = path[0] if isinstance(path, tuple) and path else path
    altitude = first[2] if isinstance(first, tuple) and len(first) == 3 else first
    return [Request("TAKE_OFF", {"ALTITUDE": altitude}), *requests]


def landed(state: Mapping[str, Any] | None) -> bool:
    """True when the check's phenomena say the drone is known to be on the ground where the mission started it (the
    catalog's flight state, landed by no behavior): a drone a LAND brought down was disarmed by it, then as here."""
    flight = (state or {}).get("flight")
    return flight is not None and getattr(flight, "state", None) == "landed" and getattr(flight, "since", 0) is None


__all__ = ["BY_PATH", "ERA_API", "NOT_ARMED", "RULE", "arms", "imports_era_api", "landed", "take_off_by_path"]
