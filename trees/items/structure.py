"""The shape of a mission's items as a tree: DO_JUMP's repeats as ``Repeat`` decorators, and the behaviors an item
starts for the items after it (a camera triggered every N meters, a video) as ``Parallel`` nodes around them.

The item converter hands over a flat list of entries, in item order: the behaviors of an item (:class:`Step`), a
jump back (:class:`Jump`) and the start or stop of a running behavior (:class:`Span`). A jump repeats the items
from its target up to itself: ``Repeat num_cycles=N+1`` over them (N: the jump's repeat count). A running behavior
runs beside the items until it is stopped (or its block ends): ``Parallel success_count=1 failure_count=1`` of a
``Sequence`` of those items and the behavior, so it stops when they are done and its failure fails them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from aeroexec.trees.model import TreeNode

FOREVER = -1  # DO_JUMP's repeat count forever (ArduPilot's AP_MISSION_JUMP_REPEAT_FOREVER), Repeat's num_cycles


@dataclass
class Step:
    """The behaviors of one item."""

    seq: int
    nodes: list[TreeNode]


@dataclass
class Jump:
    """DO_JUMP at item ``seq``: back to item ``target``, ``repeat`` more times."""

    seq: int
    target: int
    repeat: int
    line: int


@dataclass
class Span:
    """A behavior that runs beside the following items (``node``), or the end of the one of kind ``key``."""

    seq: int
    key: str
    node: TreeNode | None
    line: int


@dataclass
class _Block:
    """Items repeated by a jump."""

    entries: list
    cycles: int
    jump: Jump
    first: int = 0
    last: int = 0
    inner: list = field(default_factory=list)


Entry = Step | Jump | Span | _Block


def _first(entry: Entry) -> int:
    return entry.first if isinstance(entry, _Block) else entry.seq


def _last(entry: Entry) -> int:
    return entry.last if isinstance(entry, _Block) else entry.seq


def nest_jumps(entries: list[Entry], problem) -> list[Entry]:
    """The entries with each jump's items folded into a block; ``problem(line, message[, severity])`` hears of jumps
    that cannot be folded (forward, crossing another) and, as a warning, of one that repeats forever."""
    entries = list(entries)
    while True:
        k = next((i for i, e in enumerate(entries) if isinstance(e, Jump)), None)
        if k is None:
            return entries
        jump = entries[k]
        del entries[k]
        if jump.repeat < FOREVER:
            problem(jump.line, f"item {jump.seq}: DO_JUMP repeat count {jump.repeat}: a count is a number of "
                               f"repeats, or -1 forever")
            continue
        if jump.target >= jump.seq:
            problem(jump.line, f"item {jump.seq}: DO_JUMP to item {jump.target}, which is not before it: aeroexec "
                               f"repeats items already flown (a jump forward skips items nobody flies)")
            continue
        if jump.repeat == 0:
            continue  # jumps no time: nothing repeats
        t = next((i for i, e in enumerate(entries[:k]) if _last(e) >= jump.target), None)
        if t is None:
            problem(jump.line, f"item {jump.seq}: DO_JUMP to item {jump.target}, which the mission does not have")
            continue
        if _first(entries[t]) < jump.target:
            problem(jump.line, f"item {jump.seq}: DO_JUMP to item {jump.target}, inside the items another DO_JUMP "
                               f"repeats: jumps that cross each other have no tree")
            continue
        inner = entries[t:k]
        if jump.repeat == FOREVER:  # ArduPilot's patrol: until the mission is stopped
            problem(jump.line, f"item {jump.seq}: DO_JUMP repeats forever (repeat count -1) items "
                               f"{jump.target}-{jump.seq - 1}: the drone patrols until the mission is stopped "
                               f"(aeroexec ctl abort or suspend, the time limit --max-time, a safety rule such as low "
                               f"battery); "
                               f"the items after it never fly", "warning")
        block = _Block(inner, jump.repeat + 1 if jump.repeat != FOREVER else FOREVER, jump, _first(inner[0]),
                       jump.seq)
        entries[t:k] = [block]


def _sequence(name: str, nodes: list[TreeNode], file: str, line: int) -> TreeNode:
    return nodes[0] if len(nodes) == 1 else TreeNode("Sequence", name, {}, nodes, file, line)


def build(entries: list[Entry], file: str) -> list[TreeNode]:
    """The nodes of the (folded) entries: blocks as Repeat, spans as Parallel."""
    nodes: list[TreeNode] = []
    i = 0
    while i < len(entries):
        entry = entries[i]
        if isinstance(entry, Step):
            nodes.extend(entry.nodes)
        elif isinstance(entry, _Block):
            body = build(entry.entries, file)
            if body:
                times = "forever" if entry.cycles == FOREVER else f"{entry.cycles} times"
                name = f"items {entry.first}-{entry.last - 1} {times} (DO_JUMP item {entry.last})"
                nodes.append(TreeNode("Repeat", name, {"num_cycles": str(entry.cycles)},
                                      [_sequence(f"items {entry.first}-{entry.last - 1}", body, file,
                                                 entry.jump.line)], file, entry.jump.line))
        elif isinstance(entry, Span) and entry.node is not None:
            end = next((j for j in range(i + 1, len(entries)) if isinstance(entries[j], Span)
                        and entries[j].key == entry.key), len(entries))
            body = build(entries[i + 1:end], file)
            if body:
                last = _last(entries[end - 1])
                name = f"{entry.node.name} over items {entry.seq + 1}-{last}"
                nodes.append(TreeNode("Parallel", name, {"success_count": "1", "failure_count": "1"},
                                      [_sequence(f"items {entry.seq + 1}-{last}", body, file, entry.line),
                                       entry.node], file, entry.line))
            i = end if end < len(entries) and entries[end].node is None else end - 1
        i += 1
    return nodes
