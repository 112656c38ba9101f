"""Run one XML tree in BehaviorTree.CPP (through behaviortreepy) and in aeroexec's runtime, tick by tick.

The reference is BT.CPP 4.10; behaviortreepy embeds 4.8.2. Where 4.10 changed a result, the case says so
(``since_4_10``: 4.8.2's value and 4.10's) and 4.8.2's run is turned into 4.10's before the comparison.

Leaves are scripted: each leaf type named in ``scripts`` answers the statuses of its script in turn (cycling),
RUNNING included, in both runtimes (in BT.CPP a stateful action when its script has RUNNING, else a condition;
a py_trees leaf here); BT.CPP's halts are recorded through ``on_halted``. One BT.CPP behaviour is left out on
purpose: a StatefulActionNode ticked again after it completed, without its parent resetting it (the condition
of IfThenElse/WhileDoElse), answers its old status without running; aeroexec runs the leaf again.

What is compared after every tick, for every node (BT.CPP's uid = its place in document order, as in our
``describe``): what the tick did to it --

* ``SUCCESS``/``FAILURE``/``RUNNING``: the status it returned when ticked (a node RUNNING at the start of the
  tick and not halted was ticked again);
* ``HALTED``: it was RUNNING and was halted (BT.CPP: a transition RUNNING -> IDLE);
* ``-``: the tick neither ticked nor halted it.

Both runtimes are observed through status transitions (BT.CPP logs a status set only when it changes): BT.CPP's
from its log, aeroexec's from the statuses its nodes take while ticked and their resets (``stop(INVALID)``), with
the RUNNING that BT.CPP's control nodes and decorators set on entering a tick. BT.CPP resets completed children
to IDLE when their parent completes (and the root after every completed tick), where aeroexec keeps the status
for display until the node starts again; a reset of a completed node is no observation of its own.
BT.CPP keeps a skipped node IDLE and tells only its parent, so SKIPPED shows as ``-``
(the parent's status carries it). BT.CPP's transitions are read from its FileLogger2 (``.btlog``): records
carry system-clock microseconds, ticks are kept 20 us apart, and each tick's records are those stamped up to
just after ``tick_exactly_once`` returned (a timer's halt between two ticks belongs to the next one).
"""

from __future__ import annotations

import gc
import itertools
import re
import struct
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import behaviortreepy as bt
from aeroexec.beliefs import BeliefMemory
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees.conversions import DOUBLE, INT
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.model import TreeFormatError
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.builder import TreeBuildError, build_tree, describe, model_of
from aeroexec.trees.runtime.context import TreeContext
from aeroexec.trees.runtime.nodes.node_conditions import NodeConditions
from aeroexec.trees.runtime.ticking import TickError, TickState, attach, result_of, tick_tree
from aeroexec.trees.script import text_of
from patience import hang_guard
from py_trees.behaviour import Behaviour
from py_trees.common import Status

NAMES = {0: "IDLE", 1: "RUNNING", 2: "SUCCESS", 3: "FAILURE", 4: "SKIPPED"}
_CATALOG = default_catalog()
_RUNS = itertools.count()
_GAP = 20  # microseconds between one tick's end and the next one's start


@dataclass
class Run:
    """What one runtime did: per tick, the root's status and each node's observation; the halted leaves."""

    roots: list[str] = field(default_factory=list)
    ticks: list[list[str]] = field(default_factory=list)
    halts: list[list[str]] = field(default_factory=list)
    blackboard: dict[str, Any] = field(default_factory=dict)
    #: where the run stopped on an error: -1 when the tree was refused as it loaded, else the tick that threw
    error_at: int | None = None
    error: str = ""
    #: keys BT.CPP cannot show as text (never written, or holding a queue): left out of the comparison
    unreadable: set[str] = field(default_factory=set)
    #: when each tick began, in seconds from the first (BT.CPP's: as its steady clock measured them)
    starts: list[float] = field(default_factory=list)

    def table(self) -> str:
        rows = [f"tick {i}: root {r:8s} {' '.join(f'{s:8s}' for s in t)} halts {h}"
                for i, (r, t, h) in enumerate(zip(self.roots, self.ticks, self.halts, strict=True))]
        if self.error_at is not None:
            rows.append(f"{'load' if self.error_at < 0 else f'tick {self.error_at}'}: error {self.error}")
        return "\n".join(rows)


class Clock:
    """The engine clock of our runtime, moved by the harness as BT.CPP's wall clock moves."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class ScriptedLeaf(Behaviour):
    """A leaf answering its script's statuses in turn (cycling); records its halts in ``halts``."""

    def __init__(self, name: str, script: list[str], halts: list[str]) -> None:
        super().__init__(name)
        self.script, self.halts, self.index = script, halts, 0
        self.kind = name

    def update(self) -> Status:
        answer = self.script[self.index % len(self.script)]
        self.index += 1
        return Status[answer]

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.status == Status.RUNNING:
            self.halts.append(self.kind)


def _records(path: Path) -> tuple[int, int, list[tuple[int, int, int]]]:
    """The log's start (microseconds), its number of nodes and its records (stamp, uid, status)."""
    data = path.read_bytes()
    (length,) = struct.unpack_from("<i", data, 19)
    count = max(int(uid) for uid in re.findall(rb'_uid="(\d+)"', data[23:23 + length]))
    (start,) = struct.unpack_from("<q", data, 23 + length)
    body = data[31 + length:]
    return start, count, [(int.from_bytes(body[i:i + 6], "little"), int.from_bytes(body[i + 6:i + 8], "little"),
                           body[i + 8]) for i in range(0, len(body) - len(body) % 9, 9)]


def _observe(previous: str, statuses: list[str]) -> tuple[str, str]:
    """What one tick did to a node, from the statuses it was set to in that tick (a status equal to the one it has
    is no transition, as in BT.CPP's ``setStatus``); and its status afterwards."""
    seen = "RUNNING" if previous == "RUNNING" else "-"
    status = previous
    for new in statuses:
        if new in ("RESET", "CLEAR"):  # BT.CPP's resetChildren: a completed node back to IDLE (RESET: a stale
            if status != "RUNNING" or new == "CLEAR":  # RUNNING one, whose SKIPPED left it RUNNING, halted)
                status = "IDLE" if status != "RUNNING" else status
                continue
            new = "IDLE"
        if new == status:
            continue
        if new != "IDLE":
            seen = new
        elif status == "RUNNING":
            seen = "HALTED"
        status = new
    return seen, status


def _apply(state: dict[int, str], seen: dict[int, str], key: int, new: str, children_of: dict[int, list[int]]) -> None:
    """One status set on our side, as ``_observe`` reads BT.CPP's; a RESET that halts a node whose SKIPPED left it
    RUNNING resets its children too, as BT.CPP's halt does."""
    status = state[key]
    if new in ("RESET", "CLEAR"):
        if status != "RUNNING" or new == "CLEAR":
            state[key] = "IDLE" if status != "RUNNING" else status
            return
        seen[key], state[key] = "HALTED", "IDLE"
        for child in children_of[key]:
            _apply(state, seen, child, "RESET", children_of)
        return
    if new == status:
        return
    if new != "IDLE":
        seen[key] = new
    elif status == "RUNNING":
        seen[key] = "HALTED"
    state[key] = new


def _drain(path: Path, records: bool = True) -> None:
    """Wait until the logger's writer thread (which wakes on every record) has written what it was given: a first
    record (``records``: a tick ended, and the first tick always sets the root's status), then a file that stayed
    the same for 100 ms (a writer thread waits for a core that long on a loaded machine; BT.CPP's logger drops
    what is left unwritten when it is destroyed)."""
    size, steady, deadline = -1, 0, time.monotonic() + hang_guard(30)
    while (steady < 25 or records and not _has_records(path)) and time.monotonic() < deadline:
        time.sleep(0.004)
        now = path.stat().st_size
        steady = steady + 1 if now == size else 0
        size = now


def _has_records(path: Path) -> bool:
    data = path.read_bytes()
    if len(data) < 23:
        return False
    (length,) = struct.unpack_from("<i", data, 19)
    return len(data) >= 31 + length + 9


def run_btcpp(xml: str, scripts: dict[str, list[str]], ticks: int, folder: Path,
              between: float = 0.0, blackboard: dict[str, Any] | None = None) -> Run:
    """The tree run in BT.CPP for ``ticks`` ticks (``between`` seconds of wall time between ticks).

    Now and then (a loaded machine) the logger's writer thread writes nothing: the first tick always sets the
    root's status, so a log without records is run again (the leaves' scripts make the run deterministic).
    """
    for _ in range(3):
        run = _run_btcpp(xml, scripts, ticks, folder, between, blackboard)
        if run.error_at in (-1, 0) or (run.ticks and any(seen != "-" for seen in run.ticks[0])):
            return run
    return run


def _run_btcpp(xml: str, scripts: dict[str, list[str]], ticks: int, folder: Path,
               between: float, blackboard: dict[str, Any] | None) -> Run:
    factory = bt.BehaviorTreeFactory()
    halts: list[str] = []
    for kind, script in scripts.items():
        counter = [0]

        def answer(node: Any, script: list[str] = script, counter: list[int] = counter) -> str:
            counter[0] += 1
            return script[(counter[0] - 1) % len(script)]

        if "RUNNING" in script:
            factory.register_simple_stateful_action(kind, answer, answer,
                                                    lambda node, kind=kind: halts.append(kind))
        else:
            factory.register_simple_condition(kind, answer)
    board = bt.Blackboard.create()
    for key, value in (blackboard or {}).items():
        {int: board.set_int, float: board.set_double, str: board.set_string}[type(value)](key, value)
    try:
        tree = factory.create_tree_from_text(xml, board)
    except (RuntimeError, ValueError) as error:  # refused as it loads
        return Run(error_at=-1, error=str(error))
    path = folder / f"parity{next(_RUNS)}.btlog"
    logger = bt.FileLogger(tree, str(path))
    run = Run()
    bounds: list[tuple[int, int]] = []
    paced = first = time.monotonic()
    before = 0
    for tick in range(ticks):
        run.starts.append(time.monotonic() - first)
        start = time.time_ns() // 1000
        try:
            run.roots.append(NAMES[int(tree.tick_exactly_once())])
        except (RuntimeError, ValueError) as error:  # thrown out of the tick (std::invalid_argument: ValueError)
            run.error_at, run.error = tick, str(error)
            break
        end = time.time_ns() // 1000
        while time.time_ns() // 1000 <= end + _GAP:  # ticks far enough apart for microsecond stamps
            pass
        bounds.append((start, end))
        run.halts.append(sorted(halts[before:]))  # a timer's halt between two ticks counts for the next one
        before = len(halts)
        if between:  # ticks ``between`` seconds apart, whatever a tick took
            paced += between
            time.sleep(max(0.0, paced - time.monotonic()))
    _drain(path, records=bool(run.roots))
    del logger
    gc.collect()
    origin, count, records = _records(path)
    state = ["IDLE"] * (count + 1)
    for index, (_, end) in enumerate(bounds):
        low = bounds[index - 1][1] + _GAP // 2 if index else 0
        high = end + _GAP // 2
        by_node: dict[int, list[int]] = {}
        for stamp, uid, status in records:
            if low < origin + stamp <= high:
                by_node.setdefault(uid, []).append(status)
        row = []
        for uid in range(1, count + 1):
            seen, state[uid] = _observe(state[uid], [NAMES[code] for code in by_node.get(uid, [])])
            row.append(seen)
        run.ticks.append(row)
    for key in tree.root_blackboard().get_keys():
        try:
            run.blackboard[key] = tree.root_blackboard().get_string(key)
        except RuntimeError:
            run.unreadable.add(key)
    return run


#: Decorators that answer without setting RUNNING when they do not tick their child.
_ANSWER_WITHOUT_CHILD = ("RunOnce", "SkipUnlessUpdated", "WaitValueUpdate", "LoopInt", "LoopDouble",
                         "LoopString", "LoopBool")
#: Nodes that never set RUNNING on entering a tick (only their result is set).
_NO_RUNNING_ON_ENTRY = ("Precondition", "Switch2", "Switch3", "Switch4", "Switch5", "Switch6")


def _is_leaf(node: Behaviour) -> bool:
    model = model_of(node)
    return model is not None and not model.children and model.type != "SubTree"


def _visible_children(node: Behaviour) -> list[Behaviour]:
    found = []
    for child in node.children:
        found += _visible_children(child) if getattr(child, "hidden", False) else [child]
    return found


def _resets_children(node: Behaviour, status: Status, result: Any) -> bool:
    """Whether BT.CPP resets the children of ``node`` as a tick of it ends with ``status`` (``result``)."""
    kind = getattr(model_of(node), "type", "")
    if result == "SKIPPED":
        return kind in ("Sequence", "Fallback", "SequenceWithMemory", "AsyncSequence", "AsyncFallback",
                        "ReactiveSequence", "ReactiveFallback", "IfThenElse", "WhileDoElse", "Repeat",
                        "RetryUntilSuccessful")
    if status == Status.RUNNING:
        return kind in ("Repeat", "RetryUntilSuccessful", "KeepRunningUntilFailure", "ReactiveSequence",
                        "ReactiveFallback", "LoopInt", "LoopDouble", "LoopString", "LoopBool")
    if kind in ("SkipUnlessUpdated", "WaitValueUpdate"):
        return False
    if status == Status.FAILURE and kind == "IfThenElse" and len(node.children) == 2:
        return node.children[1].status != Status.INVALID  # the condition failed: BT.CPP leaves it as it is
    return status in (Status.SUCCESS, Status.FAILURE)


def run_aeroexec(xml: str, scripts: dict[str, list[str]], ticks: int, between: float | list[float] = 0.0,
                 blackboard: dict[str, Any] | None = None) -> Run:
    """The same tree on aeroexec's tree runtime, its clock moved ``between`` seconds between ticks, or set to each
    tick's start in turn (``between`` a list: BT.CPP's ticks as they began, ``Run.starts``)."""
    try:
        document = read_xml(xml, "parity.xml")
    except TreeFormatError as error:  # refused as it loads
        return Run(error_at=-1, error=str(error))
    clock = Clock()
    halts: list[str] = []
    engine = SimpleNamespace(catalog=_CATALOG, now=clock, memory=BeliefMemory(),
                             log=SimpleNamespace(record=lambda *a, **k: None))
    leaves = {kind: (lambda model, board, kind=kind: ScriptedLeaf(kind, scripts[kind], halts)) for kind in scripts}
    board = Blackboard(values=blackboard)
    for key, value in (blackboard or {}).items():  # BT.CPP's set<int>/set<double> type the entry
        if not isinstance(value, str):
            board.declare(key, INT if isinstance(value, int) else DOUBLE)
    try:
        root = build_tree(document, TreeContext(engine), board, leaves)
    except TreeBuildError as error:  # refused as it loads
        return Run(error_at=-1, error=str(error))
    ticking = attach(root, TickState())
    nodes = [node for _, node in describe(root)]
    events: list[tuple[int, str]] = []
    stops: list[tuple[int, int, str]] = []  # (how many nodes the tick had returned then, node, what)
    positions = {id(node) for node in nodes}
    children_of = {id(node): [id(child) for child in _visible_children(node)] for node in nodes}
    for node in root.iterate():  # every halt (resets of completed nodes: see _resets_children)
        def stop(new_status: Status, node: Behaviour = node, original: Any = node.stop) -> None:
            at = len(ticking.visits or ())
            if new_status == Status.INVALID and node.status == Status.RUNNING:
                stops.append((at, id(node), "IDLE"))
                stops.extend((at, id(child), "CLEAR") for child in _visible_children(node))
            elif new_status == Status.INVALID and result_of(node) == "SKIPPED":
                stops.append((at, id(node), "RESET"))  # BT.CPP halts the RUNNING its SKIPPED left (reactive parent)
            original(new_status)

        node.stop = stop  # type: ignore[method-assign]
    state = {id(node): "IDLE" for node in nodes}
    run = Run()
    for tick in range(ticks):
        if isinstance(between, list):
            clock.now = between[tick] if tick < len(between) else clock.now
        run.starts.append(clock.now)
        before = len(halts)
        events.clear()
        stops.clear()
        returned: dict[int, int] = {}  # node -> the place it last returned at in this tick
        try:
            visits = tick_tree(root)  # each node as it returned, as the runner sees them; the halts in between
        except TickError as error:  # as BT.CPP throws out of the tick: the run stops there
            run.error_at, run.error = tick, str(error)
            break
        for place, (ticked, result) in enumerate([*visits, (None, None)]):
            if ticked is None:  # after the root returned: the runtime shows IDLE the children a node that
                events.extend((key, what) for at, key, what in stops if at == place and what != "RESET")
                break  # started again did not reach (no halt in BT.CPP, which leaves them as they were)
            events.extend((key, what) for at, key, what in stops if at == place)
            status = Status.SUCCESS if result == "SKIPPED" else result
            kind = getattr(model_of(ticked), "type", "")
            child_ticked = bool(ticked.children) and (returned.get(id(ticked.children[0]), -1)
                                                      > returned.get(id(ticked), -1))  # since it last returned
            returned[id(ticked)] = place
            remembered = (kind in _NO_RUNNING_ON_ENTRY or (kind in _ANSWER_WITHOUT_CHILD and not child_ticked)
                          or (isinstance(ticked, NodeConditions) and not child_ticked))  # a pre-condition decided:
            # BT.CPP does not call the node's tick()
            if not _is_leaf(ticked) and not remembered:
                events.append((id(ticked), "RUNNING"))  # BT.CPP's control nodes and decorators set RUNNING first
            if result != "SKIPPED":  # BT.CPP keeps a skipped node's status
                events.append((id(ticked), "IDLE" if result == Status.INVALID else result.value))
            if id(ticked) in positions and _resets_children(ticked, status, result):
                reset = "CLEAR" if status == Status.RUNNING else "RESET"
                children = _visible_children(ticked)
                if kind == "SequenceWithMemory" and status == Status.FAILURE:
                    children = children[ticked.index:]  # BT.CPP halts from the failed child on only
                events.extend((id(child), reset) for child in children)
        seen = {key: "RUNNING" if status == "RUNNING" else "-" for key, status in state.items()}
        for key, new in events:
            if key in state:
                _apply(state, seen, key, new, children_of)
        run.ticks.append([seen[id(node)] for node in nodes])
        if root.status in (Status.SUCCESS, Status.FAILURE):
            state[id(root)] = "IDLE"  # BT.CPP's tickRoot resets a root that completed
        result = result_of(root)
        run.roots.append(result if isinstance(result, str) else "IDLE" if result == Status.INVALID else result.value)
        run.halts.append(sorted(halts[before:]))
        if not isinstance(between, list):
            clock.now += between
    run.blackboard = {key: text_of(value) for key, value in board.items()}
    return run


def _shown(run: Run, unreadable: set[str]) -> tuple:
    board = {k: v for k, v in run.blackboard.items() if k not in unreadable}
    return run.roots, run.ticks, run.halts, run.error_at, board


#: What stands for where a run stopped in a ``since_4_10`` record (the other names are blackboard keys).
ERROR_AT = "<error_at>"
#: What stands for the whole run, when 4.8.2 stops on an error (the record's old value: where) and 4.10 runs
RUN = "<run>"


@dataclass
class Expected:
    """A run as BT.CPP 4.10 gives it, read off its source, where 4.8.2 stops on an error: each tick's root status
    and node observations, and the final blackboard (no halts)."""

    roots: list[str]
    ticks: list[list[str]]
    blackboard: dict[str, str]


def as_4_10(theirs: Run, since_4_10: dict[str, tuple[Any, Any]]) -> None:
    """Turn BT.CPP 4.8.2's run (behaviortreepy) into 4.10's, where 4.10 changed the result: ``since_4_10`` maps a
    blackboard key (or ``ERROR_AT``) to (what 4.8.2 gives, what 4.10 gives). 4.8.2 must give what the record says,
    so a record that stopped being true fails the test instead of hiding a difference."""
    for what, (old, new) in since_4_10.items():
        seen = theirs.error_at if what in (ERROR_AT, RUN) else theirs.blackboard.get(what)
        assert seen == old, f"BT.CPP 4.8.2 gives {what} = {seen!r}, the record says {old!r}"
        if what == RUN:
            theirs.roots, theirs.ticks, theirs.blackboard = new.roots, new.ticks, dict(new.blackboard)
            theirs.halts, theirs.error_at, theirs.error = [[] for _ in new.roots], None, ""
        elif what == ERROR_AT:
            theirs.error_at = new
        else:
            theirs.blackboard[what] = new


def compare(xml: str, scripts: dict[str, list[str]], ticks: int, folder: Path, between: float = 0.0,
            blackboard: dict[str, Any] | None = None,
            since_4_10: dict[str, tuple[Any, Any]] | None = None) -> tuple[Run, Run]:
    """Both runs; an AssertionError showing both tables when they differ. ``since_4_10``: where BT.CPP 4.10 (the
    reference) gives another result than the 4.8.2 that behaviortreepy embeds (``as_4_10``)."""
    theirs = run_btcpp(xml, scripts, ticks, folder, between, blackboard)
    if since_4_10:
        as_4_10(theirs, since_4_10)
    # BT.CPP's timers run on its steady clock: ours is set to the times its ticks began, so a tick the harness made
    # late on a loaded machine (a starved thread) is as late in both, and a timer due before it is due in both
    ours = run_aeroexec(xml, scripts, ticks, theirs.starts if between else 0.0, blackboard)
    if _shown(theirs, theirs.unreadable) != _shown(ours, theirs.unreadable):
        raise AssertionError(f"BehaviorTree.CPP and aeroexec differ on\n{xml}\nscripts {scripts}\n"
                             f"BehaviorTree.CPP:\n{theirs.table()}\nblackboard {theirs.blackboard} (unreadable: "
                             f"{sorted(theirs.unreadable)})\n"
                             f"aeroexec:\n{ours.table()}\nblackboard {ours.blackboard}\n"
                             f"ticks began at (s) {[round(t, 3) for t in theirs.starts]}")
    return theirs, ours
