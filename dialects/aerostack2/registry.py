"""Aerostack2 registered with the core, as another package would be (pyproject.toml's entry points): its mission
interpreter's plans in the table of mission formats, its Python API served under the names its scripts import
(``as2_python_api``, ``as2_msgs``, ``rclpy``, and
``python_interface``, its name in Aerostack2 1.0; a program importing ``as2_python_api`` or ``rclpy`` is a script run
whole, with the simulated drone's namespace in its environment), and its drone interfaces in the static check
(with the drones a script only watches). (Its behavior-tree nodes are mapped through ``aeroexec.tree_mappings``.)"""

from __future__ import annotations

from aeroexec.dialects.aerostack2.formats import FORMATS
from aeroexec.engine.missions.dialect_checks import DialectChecks
from aeroexec.engine.missions.standins import StandIns

_HERE = "aeroexec.dialects.aerostack2"

IMPORTS = StandIns(
    names={name: f"{_HERE}.{name}" for name in ("rclpy", "as2_python_api", "as2_msgs", "python_interface")},
    scripts=("as2_python_api", "rclpy", "python_interface"),
    # the variable Aerostack2's simulation launch sets to the simulated drone's namespace (its examples read it)
    environment={"AEROSTACK2_SIMULATION_DRONE_ID": "drone0"},
    drones=f"{_HERE}.namespaces:script_namespaces",
)
CHECKS = DialectChecks(objects=f"{_HERE}.drone_objects:DroneObjects",
                       problems=f"{_HERE}.namespaces:watched_drones")

__all__ = ["CHECKS", "FORMATS", "IMPORTS"]
