"""Aerostack2 registered with the core, as another package would be (pyproject.toml's entry points): its mission
interpreter's plans in the table of mission formats, its Python API served under the names its scripts import
(``as2_python_api``, ``as2_msgs``, ``rclpy``, and ``python_interface``, its name in Aerostack2 before 1.0 (the
package was renamed as2_python_api in December 2022); a program importing ``as2_python_api`` or ``rclpy`` is a
script run whole, with the simulated drone's namespace in its environment), and its drone interfaces in the static
check (with the drones a script only watches; and that version's rule for a follow_path from the ground:
:mod:`.eras`). (Its behavior-tree nodes are mapped through ``aeroexec.tree_mappings``.)"""

from __future__ import annotations

import ast

from aeroexec.dialects.aerostack2.formats import FORMATS
from aeroexec.engine.missions.dialect_checks import DialectChecks
from aeroexec.engine.missions.standins import StandIns

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

_HERE = "aeroexec.dialects.aerostack2"
_API = ("as2_python_api", "python_interface")  # Aerostack2's Python API, and its name before 1.0

IMPORTS = StandIns(
    names={name: f"{_HERE}.{name}" for name in ("rclpy", "as2_python_api", "as2_msgs", "python_interface")},
    scripts=("as2_python_api", "rclpy", "python_interface"),
    # the variable Aerostack2's simulation launch sets to the simulated drone's namespace (its examples read it)
    environment={"AEROSTACK2_SIMULATION_DRONE_ID": "drone0"},
    drones=f"{_HERE}.namespaces:script_namespaces",
    # its behavior runs (behavior_runs.py) are not journaled calls of the mission API: such a mission is not resumed
    unjournaled={api: f"Aerostack2's Python API ({api})" for api in _API},
)
CHECKS = DialectChecks(objects=f"{_HERE}.registry:drone_objects", problems=f"{_HERE}.registry:script_problems")


def script_problems(nodes: list[ast.AST], dotted: Any) -> list[tuple[Any, ...]]:
    """The problems of a whole program (``problems`` of :data:`CHECKS`): the drones it only watches
    (:func:`.namespaces.watched_drones`), its own ROS 2 nodes' uses of a graph and spins nothing ends
    (:func:`.ros_nodes.node_problems`), and a script of ``rclpy`` alone, which flies nothing
    (:func:`.ros_nodes.flies_nothing`)."""
    from aeroexec.dialects.aerostack2.namespaces import watched_drones
    from aeroexec.dialects.aerostack2.ros_nodes import flies_nothing, node_problems

    alone = [] if any(_names_api(node) for node in nodes) else flies_nothing(nodes, dotted)
    return [*watched_drones(nodes, dotted), *node_problems(nodes, dotted), *alone, *_era_rules(nodes)]


def _era_rules(nodes: list[ast.AST]) -> list[tuple[Any, ...]]:
    """A warning naming the rule of an earlier era a script is flown by (:mod:`.eras`): its follow_path from the
    ground, for a script importing python_interface that follows a path."""
    if not any(isinstance(n, ast.Attribute) and n.attr == "follow_path" for n in nodes):
        return []
    from aeroexec.dialects.aerostack2.eras import NOT_ARMED, RULE, arms, imports_era_api

    imported = imports_era_api(nodes)
    if imported is None:
        return []
    return [(imported, "warning", RULE if arms(nodes) else NOT_ARMED)]



class _NoDrones:
    """The drone interfaces of a program that never names Aerostack2's API: none (what :class:`.DroneObjects` finds
    in such a program: no call of it runs behaviors, none is reported)."""

    several = False

    def check(self, call: ast.Call) -> None:
        return None

    def sequence_requests(self, call: ast.Call, state: Any = None) -> list[tuple[str, str | None, dict[str, Any],
                                                                                set[str]]]:
        return []

    def runs_behaviors(self, call: ast.Call) -> bool:
        return False


def _names_api(node: ast.AST) -> bool:
    if isinstance(node, ast.Import):
        return any(api in alias.name for alias in node.names for api in _API)
    if isinstance(node, ast.ImportFrom):
        return any(api in (node.module or "") or any(api in alias.name for alias in node.names) for api in _API)
    return isinstance(node, ast.Constant) and isinstance(node.value, str) and any(api in node.value for api in _API)


def drone_objects(checker: Any) -> Any:
    """Aerostack2's drone interfaces in the program ``checker`` checks (:class:`.drone_objects.DroneObjects`, the
    ``objects`` of :data:`CHECKS`). A drone interface is found through an import of Aerostack2's API (or a text naming
    it): a program with neither has none, and is answered without importing the API's tables (~4 ms of the check of
    every Python mission, ``bench/startup.py``)."""
    if not any(_names_api(node) for node in checker.nodes):
        return _NoDrones()
    from aeroexec.dialects.aerostack2.drone_objects import DroneObjects  # here: only a program that may use them

    return DroneObjects(checker)


__all__ = ["CHECKS", "FORMATS", "IMPORTS", "drone_objects", "script_problems"]
