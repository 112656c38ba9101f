"""Aerostack2's mission-interpreter missions (JSON or YAML) into the tree model: a plan of behavior calls run one
after another, each call the catalog requests it stands for (:mod:`aeroexec.dialects.aerostack2.behaviors`)::

    {"target": "drone0", "verbose": false,
     "plan": [{"behavior": "takeoff", "method": "__call__", "args": {"height": 2.0, "speed": 1.0}},
              {"behavior": "go_to", "args": {"x": 5.0, "y": 5.0, "z": 2.0, "speed": 1.0, "yaw_mode": 1}},
              {"behavior": "land", "args": {"speed": 0.5}}]}

becomes a ``SequenceWithMemory`` of ``TAKE_OFF ALTITUDE=2.0``, ``GO_TO_POINT COORDINATES=5.0, 5.0, 2.0 SPEED=1.0``
and ``LAND``, each node named after the call and placed at its item's line. The plan stops at an item that fails
(Aerostack2's interpreter goes on to the next one): a tree mission that did not do what it was asked does not end
"completed". ``target`` names the drone (any name, when one drone flies); ``verbose`` and ``use_sim_time`` are read
and ignored. GPS points (``go_to_gps``) are placed from ``home``, the world's home point.
"""

from __future__ import annotations

import logging
import math
import re
from pathlib import Path
from typing import Any

import yaml
from aeroexec.dialects.aerostack2 import behaviors as aerostack2
from aeroexec.dialects.aerostack2.behaviors import As2Error, Request
from aeroexec.drones.geodesy import Geodetic
from aeroexec.engine.yaml_nodes import MAP, NodeReader
from aeroexec.trees.loaders.common import errors_of
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode

from aeroexec.limits import MAX_NUMBER_LENGTH, InputError, read_text

logger = logging.getLogger(__name__)

_KEYS = ("target", "plan", "verbose", "use_sim_time")
_ITEM_KEYS = ("behavior", "method", "args")
MAIN = "Aerostack2Mission"


def read_plan_tree(data: str | bytes, file: str, home: Geodetic | None = None) -> TreeDocument:
    """Aerostack2's mission interpreter plan (JSON or YAML), as the table of mission formats reads a file."""
    from aeroexec.trees.mission_file import text_of

    return read_aerostack2_plan(text_of(data, file), file, home)


def is_aerostack2_plan(text: str) -> bool:
    """True when a JSON or YAML text is an interpreter mission (a mapping with ``target`` and ``plan``): a look at
    its top-level keys, without reading the rest."""
    head = text.lstrip("\ufeff \t\r\n")
    return ('"plan"' in text and '"target"' in text) if head.startswith("{") else (
        any(line.startswith(("plan:", "target:")) for line in text.splitlines()))


def read_aerostack2_plan(text: str, file: str, home: Geodetic | None = None) -> TreeDocument:
    """An interpreter mission from JSON or YAML text (JSON is read as the YAML it also is, with its lines)."""
    reader = NodeReader(text, file)
    root = reader.root
    nodes: list[TreeNode] = []
    if root is None and not reader.failed:
        reader.error_at(0, "the file is empty: expected an Aerostack2 mission {target, plan}")
    elif root is not None:
        nodes = _plan(reader, root, tuple(home) if home is not None else None)
    if reader.failed:
        raise TreeFormatError(errors_of(reader))
    sequence = TreeNode("SequenceWithMemory", "plan", {}, nodes, file, root.start_mark.line + 1 if root else 0)
    return TreeDocument({MAIN: sequence}, MAIN, file, {MAIN: sequence.line})


def load_aerostack2_plan(path: str | Path, home: Geodetic | None = None) -> TreeDocument:
    """An interpreter mission from a ``.json``, ``.yaml`` or ``.yml`` file."""
    try:
        text = read_text(path)
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return read_aerostack2_plan(text, str(path), home)


def _plan(reader: NodeReader, root: yaml.Node, home: tuple[float, ...] | None) -> list[TreeNode]:
    entries = reader.mapping(root, "the mission", _KEYS) if root.tag == MAP else None
    if entries is None:
        if root.tag != MAP:
            reader.error(root, f"an Aerostack2 mission is a mapping {{target, plan}}, not {reader.shown(root)}")
        return []
    for key in ("target", "plan"):
        if key not in entries:
            reader.error(root, f"the mission has no {key}: an Aerostack2 mission is {{target, plan}}")
    if "target" in entries:
        target = reader.text(entries["target"][1], "target")
        logger.debug("%s: the mission's target is %s", reader.file, target)
    items = reader.sequence(entries["plan"][1], "plan") if "plan" in entries else None
    nodes = []
    for index, item in enumerate(items or (), start=1):
        node = _item(reader, item, index, home)
        if node is not None:
            nodes.append(node)
    if items == []:
        reader.error(entries["plan"][1], "the plan is empty: nothing to fly")
    return nodes


def _item(reader: NodeReader, item: yaml.Node, index: int, home: tuple[float, ...] | None) -> TreeNode | None:
    what = f"plan item {index}"
    entries = reader.mapping(item, what, _ITEM_KEYS)
    if entries is None:
        return None
    if "behavior" not in entries:
        reader.error(item, f"{what} has no behavior (takeoff, go_to, follow_path, land...)")
        return None
    behavior = reader.text(entries["behavior"][1], f"{what}: behavior")
    method = reader.text(entries["method"][1], f"{what}: method") if "method" in entries else "__call__"
    args: dict[str, Any] = {}
    if "args" in entries:
        value = _value(reader, entries["args"][1])
        if isinstance(value, dict) and all(isinstance(k, str) for k in value):
            args = value
        elif not reader.is_null(entries["args"][1]):
            reader.error(entries["args"][1], f"{what}: args must be a mapping of argument names to values")
            return None
    if behavior is None or method is None:
        return None
    line = item.start_mark.line + 1
    try:
        call = aerostack2.method(behavior, method)
        requests = aerostack2.requests(call, call.bind((), args), home=home)
    except As2Error as error:
        reader.error(item, f"{what}: {error.message}")
        return None
    if any(isinstance(v, aerostack2.Unplaced) for r in requests for v in r.arguments.values()):
        reader.error(item, f"{what}: {call.spelled}() takes GPS points, and there is no home point to place them "
                           f"from (give a world, or --home LAT,LON)")
        return None
    leaves = [_leaf(request, call.spelled, reader.file, line) for request in requests]
    if len(leaves) == 1:
        return leaves[0]
    return TreeNode("SequenceWithMemory", call.spelled, {}, leaves, reader.file, line)


_JSON_NUMBER = re.compile(r"-?(0|[1-9]\d*)(\.\d+)?[eE][+-]?\d+")


def _value(reader: NodeReader, node: yaml.Node) -> Any:
    """A node's value; a plain ``1e-3`` is the number JSON (and YAML 1.2) reads, not YAML 1.1's text."""
    if isinstance(node, yaml.ScalarNode) and node.style is None and _JSON_NUMBER.fullmatch(str(node.value)) \
            and len(node.value) <= MAX_NUMBER_LENGTH:
        number = float(node.value)
        return number if math.isfinite(number) else node.value
    if isinstance(node, yaml.SequenceNode):
        return [_value(reader, item) for item in node.value]
    if node.tag == MAP:
        keys = [reader.value(k) for k, _ in node.value]
        return dict(zip(keys, (_value(reader, v) for _, v in node.value), strict=True)) \
            if all(isinstance(k, str) for k in keys) else reader.value(node)
    return reader.value(node)


def _leaf(request: Request, name: str, file: str, line: int) -> TreeNode:
    return TreeNode(request.behavior, name, {k: port_text(v) for k, v in request.arguments.items()}, [], file, line)


def port_text(value: Any) -> str:
    """A Python value as port text: ``(1, 2, 3)`` is ``"1, 2, 3"``, a path ``"[[1, 2, 3], [4, 5, 6]]"``."""
    if isinstance(value, list | tuple):
        if any(isinstance(v, list | tuple) for v in value):
            return "[" + ", ".join(f"[{port_text(v)}]" if isinstance(v, list | tuple) else port_text(v)
                                   for v in value) + "]"
        return ", ".join(port_text(v) for v in value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


__all__ = ["MAIN", "is_aerostack2_plan", "load_aerostack2_plan", "port_text", "read_aerostack2_plan"]
