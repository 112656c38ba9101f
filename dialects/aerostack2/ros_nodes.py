"""The static check of a script's own ROS 2 nodes (``rclpy.node.Node``, a class of the script's derived from it,
``rclpy.create_node``): what of them needs a ROS 2 graph, and spins that nothing can end.

aeroexec serves a node's logger, name, parameters, clock, timers and publishers of messages used as data
(:mod:`aeroexec.dialects.aerostack2.rclpy.node`); a call of its other methods (``create_subscription``,
``create_client``, ``create_service``...) is an error at its line: this mission uses ROS 2 beyond the drone
interface. A spin (``rclpy.spin(node)``, an executor's ``spin()``) of the script's nodes when the script creates
no timer and starts no thread would never end — nothing aeroexec serves calls back into it — and is refused before
flight at its line, as a ``while True:`` with no way out is.
"""

from __future__ import annotations

import ast
import sys

from aeroexec.dialects.aerostack2.node_api import needs_graph
from aeroexec.dialects.ros import ROS2_BEYOND

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: What makes a node: the class, and the function.
NODE_MAKERS = ("rclpy.node.Node", "rclpy.create_node")
WRONG_SEQUENCE = "WRONG_SEQUENCE"


def node_problems(nodes: list[ast.AST], dotted: Any) -> list[tuple[Any, ...]]:
    """``(node, severity, message[, kind])`` for each use of a script's node that needs a ROS 2 graph, and each
    spin of its nodes that nothing can end."""
    if not any(_imports_rclpy(n) for n in nodes):
        return []
    classes = _node_classes(nodes, dotted)
    names, attributes, executors, added = _node_names(nodes, dotted, classes)
    problems: list[tuple[Any, ...]] = []
    for cls in (n for n in nodes if isinstance(n, ast.ClassDef) and n.name in classes):
        for node in ast.walk(cls):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "self" \
                    and needs_graph(node.attr):
                problems.append((node, "error", f"Node.{node.attr}: {ROS2_BEYOND}"))
    for node in nodes:
        if isinstance(node, ast.Attribute) and needs_graph(node.attr) and _is_node(node.value, names, attributes):
            problems.append((node, "error", f"Node.{node.attr}: {ROS2_BEYOND}"))
    timers = any(isinstance(n, ast.Attribute) and n.attr == "create_timer" for n in nodes)
    threads = any(isinstance(n, ast.Call) and (dotted(n.func) or "").startswith(("threading.Thread",
                                                                                 "concurrent.futures"))
                  for n in nodes)
    if timers or threads:
        return problems
    for call in (n for n in nodes if isinstance(n, ast.Call)):
        spun = _spun(call, dotted, names, attributes, executors, added, classes)
        if spun is not None:
            problems.append((call, "error", f"This mission never ends: {spun} runs its node's callbacks until "
                                            f"rclpy.shutdown(), and the script gives it none (no create_timer) and "
                                            f"no thread to shut it down; aeroexec serves no subscriptions, services "
                                            f"or actions that could call back. Give the node a timer whose callback "
                                            f"ends the mission with rclpy.shutdown(), or spin_once with a "
                                            f"timeout_sec", WRONG_SEQUENCE))
    return problems


def _imports_rclpy(node: ast.AST) -> bool:
    if isinstance(node, ast.Import):
        return any(alias.name.partition(".")[0] == "rclpy" for alias in node.names)
    return isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").partition(".")[0] == "rclpy"


def _node_classes(nodes: list[ast.AST], dotted: Any) -> set[str]:
    """The script's classes derived from ``rclpy.node.Node`` (or from one of them)."""
    defined = [n for n in nodes if isinstance(n, ast.ClassDef)]
    found: set[str] = set()
    grew = True
    while grew:
        grew = False
        for cls in defined:
            if cls.name not in found and any(dotted(b) == NODE_MAKERS[0] or (isinstance(b, ast.Name) and b.id in found)
                                             for b in cls.bases):
                found.add(cls.name)
                grew = True
    return found


def _makes_node(value: ast.AST, dotted: Any, classes: set[str]) -> bool:
    if not isinstance(value, ast.Call):
        return False
    return dotted(value.func) in NODE_MAKERS or (isinstance(value.func, ast.Name) and value.func.id in classes)


def _node_names(nodes: list[ast.AST], dotted: Any, classes: set[str]
                ) -> tuple[set[str], set[str], set[str], dict[str, list[ast.AST]]]:
    """Names bound to a node, ``self.X`` attributes bound to one, names bound to an executor, and the nodes added
    to each executor."""
    names: set[str] = set()
    attributes: set[str] = set()
    executors: set[str] = set()
    added: dict[str, list[ast.AST]] = {}
    for node in nodes:
        if isinstance(node, ast.Assign | ast.AnnAssign) and node.value is not None:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            made = _makes_node(node.value, dotted, classes)
            executor = isinstance(node.value, ast.Call) and (dotted(node.value.func) or "").startswith(
                "rclpy.executors.")
            for target in targets:
                if isinstance(target, ast.Name) and made:
                    names.add(target.id)
                elif isinstance(target, ast.Attribute) and made:
                    attributes.add(target.attr)
                elif isinstance(target, ast.Name) and executor:
                    executors.add(target.id)
    for node in nodes:
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "add_node" \
                and isinstance(node.func.value, ast.Name) and node.func.value.id in executors and node.args:
            added.setdefault(node.func.value.id, []).append(node.args[0])
    return names, attributes, executors, added


def _is_node(value: ast.AST, names: set[str], attributes: set[str]) -> bool:
    return (isinstance(value, ast.Name) and value.id in names) or \
        (isinstance(value, ast.Attribute) and value.attr in attributes)


def _spun(call: ast.Call, dotted: Any, names: set[str], attributes: set[str], executors: set[str],
          added: dict[str, list[ast.AST]], classes: set[str]) -> str | None:
    """What ``call`` spins, in the mission's words, when it spins only the script's own nodes until shutdown."""
    def local(node: ast.AST) -> bool:
        return _is_node(node, names, attributes) or _makes_node(node, dotted, classes)

    if dotted(call.func) == "rclpy.spin" and call.args and local(call.args[0]):
        return "rclpy.spin()"
    func = call.func
    if isinstance(func, ast.Attribute) and func.attr == "spin" and isinstance(func.value, ast.Name) \
            and func.value.id in executors and added.get(func.value.id) and all(map(local, added[func.value.id])):
        return f"{func.value.id}.spin()"
    return None


def flies_nothing(nodes: list[ast.AST], dotted: Any) -> list[tuple[Any, ...]]:
    """An error for a script of ``rclpy`` alone: one that starts ROS 2 (``rclpy.init()``), imports no drone interface of
    Aerostack2's Python API and nothing of its own folder (the caller knows it names no API; here: every import is
    ROS's or Python's), and so
    flies no drone — run alone, under ``python3`` too, the drone stays on the ground. Its publishers' topics say
    what it is for: another program's input (project_gazebo's ``mission_behavior_tree.py`` publishes ``start`` for
    the behavior tree that ``as2_behavior_tree`` runs and that waits for it)."""
    from aeroexec.dialects.ros import is_ros

    if not any(_imports_rclpy(n) for n in nodes) or \
            not any(isinstance(n, ast.Call) and dotted(n.func) == "rclpy.init" for n in nodes):
        return []  # a module of rclpy's nodes that a script imports is no script: the script starts ROS 2
    for node in nodes:
        if isinstance(node, ast.ImportFrom) and node.level:
            return []
        modules = [a.name for a in node.names] if isinstance(node, ast.Import) else \
            [node.module or ""] if isinstance(node, ast.ImportFrom) else []
        if any(not is_ros(m) and m.partition(".")[0] not in sys.stdlib_module_names for m in modules):
            return []
    topics = [(call, call.args[1].value) for call in nodes
              if isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute)
              and call.func.attr == "create_publisher" and len(call.args) > 1
              and isinstance(call.args[1], ast.Constant) and isinstance(call.args[1].value, str)]
    where = topics[0][0] if topics else next(n for n in nodes if _imports_rclpy(n))
    heard = (f"It publishes {', '.join(repr(t) for _, t in topics)} (line {where.lineno}) for another program: the "
             f"one that flies the drone (a behavior tree waiting for it with WaitForEvent flies with aeroexec run "
             f"TREE.xml --event {topics[0][1]}=VALUE)") if topics else \
        "It makes ROS 2 nodes of its own and no drone interface"
    return [(where, "error", f"Nothing in this script flies a drone: it uses no drone interface of Aerostack2's "
                             f"Python API (as2_python_api's DroneInterface), so run alone, under python3 too, the "
                             f"drone stays on the ground. {heard}")]


__all__ = ["NODE_MAKERS", "flies_nothing", "node_problems"]
