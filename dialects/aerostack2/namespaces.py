"""The drones an Aerostack2 script flies, by the namespaces it gives them, read from its source as
``python3 script.py`` would run it (no arguments: its argparse defaults apply).

A namespace is a string given as a drone interface's first argument (``DroneInterface('drone_sim_0')``,
``DroneInterface(drone_id="cf0")``), the default of an argparse option whose name says it holds namespaces or drone
names (``--namespaces`` with ``default=['drone0', 'drone1', 'drone2']``, ``--leader_namespace``), or a list of
strings bound to such a name (``drones_namespaces = ['cf0', 'cf1']``). Several namespaces make ``aeroexec run`` fly
the script as a fleet made for it, one drone per namespace.
"""

from __future__ import annotations

import ast
import re

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: Names (of an option, a variable, a keyword) that hold drone namespaces (compiled on first use, by re's cache).
_NAMESPACE = r"(?i)(namespace|^ns$|_ns$|^ns_|drone_?(id|name)s?$|^drones?$|^uavs?$|leader|follower)"
_INTERFACES = ("DroneInterface", "DroneInterfaceBase", "DroneInterfaceGPS", "DroneInterfaceTeleop")
_NAME_ARGUMENTS = ("drone_id", "namespace", "drone_name")


def _strings(node: ast.AST | None) -> list[str]:
    """The strings of a constant string or a list/tuple of them; empty for anything else."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, ast.List | ast.Tuple) and node.elts and all(
            isinstance(e, ast.Constant) and isinstance(e.value, str) for e in node.elts):
        return [e.value for e in node.elts]  # type: ignore[attr-defined]
    return []


def _called(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""


def _option(node: ast.Call) -> str:
    """The option an ``add_argument`` call declares (its ``dest``, or its longest name)."""
    for keyword in node.keywords:
        if keyword.arg == "dest" and isinstance(keyword.value, ast.Constant):
            return str(keyword.value.value)
    names = [a.value for a in node.args if isinstance(a, ast.Constant) and isinstance(a.value, str)]
    return max(names, key=len).lstrip("-") if names else ""


def _namespace(text: str) -> bool:
    return bool(text) and bool(re.fullmatch(r"[A-Za-z_][\w/]*", text)) and "/" not in text.strip("/")


def script_namespaces(tree: ast.Module) -> tuple[str, ...]:
    """The namespaces of the drones ``tree`` flies, in the order the script names them, each once."""
    found: dict[str, None] = {}
    own_classes = {n.name for n in ast.walk(tree) if isinstance(n, ast.ClassDef)
                   and any(isinstance(b, ast.Name | ast.Attribute) and (getattr(b, "id", None) or
                                                                       getattr(b, "attr", None)) in _INTERFACES
                           for b in n.bases)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            called = _called(node)
            if called in (*_INTERFACES, *own_classes):
                given = node.args[0] if node.args else next(
                    (k.value for k in node.keywords if k.arg in _NAME_ARGUMENTS), None)
                found.update(dict.fromkeys(s for s in _strings(given) if _namespace(s)))
            elif called == "add_argument" and re.search(_NAMESPACE, _option(node)):
                default = next((k.value for k in node.keywords if k.arg == "default"), None)
                found.update(dict.fromkeys(s for s in _strings(default) if _namespace(s)))
        elif isinstance(node, ast.Assign) and len(_strings(node.value)) > 1 and any(
                isinstance(t, ast.Name) and re.search(_NAMESPACE, t.id) for t in node.targets):
            found.update(dict.fromkeys(s for s in _strings(node.value) if _namespace(s)))
    return tuple(found)


__all__ = ["script_namespaces"]


def watched_drones(nodes: list[ast.AST], dotted: Any) -> list[tuple[ast.AST, str, str]]:
    """``(node, severity, message)`` for each ``DroneInterfaceBase(...)`` that only watches a drone another
    program flies (rss24_demo's leader waits for its followers to take off): the script gives it no behavior
    module, and waits in a loop on a drone's state (``while ... .info[...]``). Run alone, nothing would ever fly
    that drone and the wait would last until the time limit; a fleet file gives each drone its own program."""
    waits = [n for n in nodes if isinstance(n, ast.While)
             and any(isinstance(a, ast.Attribute) and a.attr == "info" for a in ast.walk(n.test))]
    modules_given = any(isinstance(n, ast.Call) and any(k.arg == "drone" for k in n.keywords) for n in nodes)
    if not waits or modules_given:
        return []
    loop = min(waits, key=lambda n: n.lineno)
    return [(node, "error", f"DroneInterfaceBase only watches its drone: nothing in this script flies it (no "
                            f"behavior module is given it), and the script waits for a drone's state (the loop at "
                            f"line {loop.lineno}); another program flies that drone. Fly them together, each "
                            f"drone with its own program, in a fleet file (aeroexec fleet)")
            for node in nodes if isinstance(node, ast.Call)
            and (dotted(node.func) or "").endswith("DroneInterfaceBase")
            and (dotted(node.func) or "").startswith(("as2_python_api", "python_interface"))]
