"""What a change's target names in a running tree mission, and the mission's items (``aeroexec ctl items``).

A target is an item number or a node's name. In a QGroundControl plan or waypoint file, item N is a MAVLink item as
QGroundControl numbers it: the nodes named ``item N ...`` (a waypoint's GO_TO_POINT and its hold, a camera span),
side by side in one sequence; an item inserted in flight is named by its own name. In any other tree, item N is the
N-th child (from 1) of the mission's main sequence: the first Sequence or SequenceWithMemory from the root down
through decorators and subtrees. A name is any visible node's, when one node has it.
"""

from __future__ import annotations

import re
from typing import Any

from aeroexec.engine.supervision.changes import ITEM_DIGITS, ChangeError, shown
from aeroexec.trees.runtime.builder import model_of
from aeroexec.trees.runtime.nodes.controls import Sequence
from aeroexec.trees.runtime.nodes.decorators import Decorator
from aeroexec.trees.runtime.nodes.node_conditions import NodeConditions
from aeroexec.trees.runtime.ticking import FAILURE, status_name
from py_trees.behaviour import Behaviour

ITEM = re.compile(r"item (\d+) ")  # the nodes of a plan's item N are named "item N ..."


class MissionItems:
    """The items of one running :class:`~aeroexec.trees.runtime.runner.TreeMission`, and what targets name in it."""

    def __init__(self, mission: Any) -> None:
        self.mission = mission
        self.plan_items = hasattr(mission.document, "item_lines")  # a QGroundControl plan or waypoint file

    def visible(self) -> list[Behaviour]:
        return [node for _, node in self.mission.nodes]

    def main_sequence(self) -> Behaviour | None:
        """The sequence whose children are the mission's items: the first Sequence (or SequenceWithMemory) from the
        root down through decorators and subtrees."""
        node = self.mission.root
        while node is not None:
            node = inner(node)
            if is_sequence(node):
                return node
            node = node.children[0] if isinstance(node, Decorator) and node.children else None
        return None

    def span(self, target: str) -> tuple[Behaviour, int, list[Behaviour]]:
        """The nodes a target names: their parent, the first one's place in it, and the nodes (siblings in order)."""
        target = target.strip()
        if re.fullmatch(ITEM_DIGITS, target):
            nodes = self._item(int(target))
        else:
            nodes = [n for n in self.visible() if n.name == target]
            if not nodes and target.lstrip("+-").isnumeric():  # "²", "-1", 5,000 digits: meant as an item number
                raise ChangeError(f"{shown(target)} is not an item number of the mission (items are numbered 1, 2, "
                                  f"3... in the digits 0-9: aeroexec ctl items lists them)")
            if not nodes:
                raise ChangeError(f"the mission has no node named {shown(target, 80)} (aeroexec ctl items lists its "
                                  f"items)")
            if len(nodes) > 1:
                places = ", ".join(_where(n) for n in nodes[:5])
                raise ChangeError(f"{len(nodes)} nodes are named {target!r} ({places}): name the item by its number")
        parent = nodes[0].parent
        if parent is None:
            raise ChangeError(f"{target!r} is the mission's root: load a new mission to change all of it")
        places = [place(parent, n) for n in nodes]
        if any(p is None for p in places) or places != list(range(places[0], places[0] + len(nodes))):
            raise ChangeError(f"item {target} is spread over the tree (its nodes are not side by side): change its "
                              f"nodes by name")
        return parent, places[0], nodes

    def _item(self, number: int) -> list[Behaviour]:
        if self.plan_items:
            matching = [n for n in self.visible() if item_of(n) == number]
            nodes = [n for n in matching if not any(item_of(a) == number for a in ancestors(n))]
            if nodes:
                return nodes
            known = sorted({item_of(n) for n in self.visible()} - {None})
            said = self._item_name(number)
            raise ChangeError(f"item {number}{said} has no behavior of its own in the mission (items with "
                              f"behaviors: {_ranges(known)})" if said else
                              f"the plan has no item {number} (items with behaviors: {_ranges(known)})")
        sequence = self.main_sequence()
        if sequence is None:
            raise ChangeError("the mission has no main sequence whose items have numbers: name the node instead")
        if not 1 <= number <= len(sequence.children):
            raise ChangeError(f"the mission has items 1 to {len(sequence.children)}, not {number}")
        return [sequence.children[number - 1]]

    def _item_name(self, number: int) -> str:
        mission = getattr(self.mission.document, "mission", None)
        item = next((i for i in getattr(mission, "items", ()) if i.seq == number), None)
        return f" ({item.name})" if item is not None else ""

    def items(self) -> list[dict[str, Any]]:
        """The mission's items, in order: number (a plan's inserted items: ``new``, named by their name), name(s),
        and whether done, running, skipped or to come."""
        listed: list[tuple[str, list[Behaviour]]] = []
        if self.plan_items:
            groups: dict[int, list[Behaviour]] = {}
            for node in self.visible():
                number = item_of(node)
                if number is not None and not any(item_of(a) == number for a in ancestors(node)):
                    if number not in groups:
                        groups[number] = []
                        listed.append((str(number), groups[number]))
                    groups[number].append(node)
                elif number is None and inserted(node) and not any(inserted(a) for a in ancestors(node)):
                    listed.append(("new", [node]))
        else:
            sequence = self.main_sequence()
            listed = [(str(i), [child]) for i, child in enumerate(sequence.children, 1)] if sequence else []
        return [{"item": number, "name": " / ".join(n.name for n in nodes), "status": _state(nodes),
                 "line": getattr(model_of(nodes[0]), "line", 0)} for number, nodes in listed]


# -- the tree's nodes -------------------------------------------------------------------------------------------
def inner(node: Behaviour) -> Behaviour:
    return node.decorated if isinstance(node, NodeConditions) else node


def is_sequence(node: Any) -> bool:
    return isinstance(node, Sequence) and node.stop_on is FAILURE


def is_fallback(node: Any) -> bool:
    return isinstance(node, Sequence) and node.stop_on is not FAILURE


def ancestors(node: Behaviour) -> list[Behaviour]:
    found, parent = [], node.parent
    while parent is not None:
        found.append(parent)
        parent = parent.parent
    return found


def walk(root: Behaviour) -> list[Behaviour]:
    found, stack = [], [root]
    while stack:
        node = stack.pop()
        found.append(node)
        stack.extend(reversed(node.children))
    return found


def place(parent: Behaviour, node: Behaviour) -> int | None:
    return next((i for i, child in enumerate(parent.children) if child is node), None)


def item_of(node: Any) -> int | None:
    match = ITEM.match(getattr(node, "name", "") or "")
    return int(match.group(1)) if match else None


def inserted(node: Any) -> bool:
    """True for a node a change brought (its model was read from a fragment, ``change N``)."""
    model = model_of(node)
    return model is not None and model.file.startswith("change ")


def label(node: Behaviour) -> str:
    """The node's name, with its line (or the change that brought it) when its name is no plan item's."""
    model = model_of(node)
    if model is None or ITEM.match(node.name):
        return node.name
    if model.file.startswith("change "):
        return f"{node.name} ({model.file})"
    return f"{node.name} (line {model.line})" if model.line else node.name


def labels(nodes: list[Any]) -> str:
    names = [n.name for n in nodes]
    return ", ".join(names[:4]) + (f" and {len(names) - 4} more" if len(names) > 4 else "") if names else "nothing"


def _where(node: Behaviour) -> str:
    model = model_of(node)
    return f"line {model.line}" if model is not None and model.line else type(node).__name__


def _state(nodes: list[Behaviour]) -> str:
    names = [status_name(n) for n in nodes]
    if "RUNNING" in names:
        return "running"
    if all(n == "SKIPPED" for n in names):
        return "skipped"
    if all(n in ("SUCCESS", "SKIPPED") for n in names):
        return "done"
    if any(n == "FAILURE" for n in names) and nodes[0].status is FAILURE:
        return "failed"
    return "to come"


def _ranges(numbers: list[int]) -> str:
    if not numbers:
        return "none"
    parts, start, last = [], numbers[0], numbers[0]
    for number in numbers[1:]:
        if number != last + 1:
            parts.append(f"{start}-{last}" if last > start else str(start))
            start = number
        last = number
    parts.append(f"{start}-{last}" if last > start else str(start))
    return ", ".join(parts)


__all__ = ["ITEM", "MissionItems", "ancestors", "inner", "is_fallback", "is_sequence", "item_of", "label", "labels",
           "place", "walk"]
