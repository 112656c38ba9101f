"""Groot2 replay files (``.btlog``) of tree missions in BehaviorTree.CPP's current FileLogger2 format: a writer that
follows a :class:`~aeroexec.trees.runtime.runner.TreeMission` tick by tick, and a reader that checks a file against
the format.

The format (BehaviorTree.CPP 4.3 to 4.10, ``src/loggers/bt_file_logger_v2.cpp``), every number little-endian:

- 18 bytes ``BTCPP4-FileLogger2``, then the protocol byte 1;
- 4 bytes: N, the size of the XML (int32), then N bytes: the tree as ``WriteTreeToXML(tree, true, true)`` prints
  it (:mod:`aeroexec.trees.groot.tree_xml`);
- 8 bytes: the first timestamp (int64, microseconds since the Unix epoch);
- then 9 bytes per transition: 6 bytes of microseconds since the first timestamp, the node's uid (uint16), the new
  status (uint8: IDLE 0, RUNNING 1, SUCCESS 2, FAILURE 3, SKIPPED 4).

Uids are the nodes' 1-based places in document order, subtrees expanded, as BehaviorTree.CPP numbers them. The
transitions are the ones BehaviorTree.CPP logs for the same ticks (:class:`TransitionTracker`): control nodes and
decorators go RUNNING when ticked, a reactive one's other children go IDLE while one runs, a node's children go
back to IDLE when it completes (a decorator's as soon as its child completes), halted nodes go IDLE deepest first
(a completed child keeps its own children's statuses), and the root goes IDLE after a completed tick. Timestamps
are engine time, so a simulated run replays at its simulated pace. What may differ from BehaviorTree.CPP's file:
the order of the port attributes of a node with more than one (a hash map's order there; ours is right for small
maps) and ``<TreeNodesModel>``, which lists our palette's models of the node types in the tree, not
BehaviorTree.CPP's built-in ones.
"""

from __future__ import annotations

import contextlib
import logging
import os
import struct
import threading
import time
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import defusedxml.ElementTree as SafeElementTree
from aeroexec.trees.groot.tree_xml import tree_xml
from aeroexec.trees.runtime.builder import model_of
from aeroexec.trees.runtime.kinds import Btlog, kind_of
from aeroexec.trees.runtime.ticking import status_name
from py_trees.behaviour import Behaviour

from aeroexec.limits import InputError, read_bytes

logger = logging.getLogger(__name__)

MAGIC = b"BTCPP4-FileLogger2"
PROTOCOL = 1
RECORD = 9
STATUS_CODES = {"IDLE": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3, "SKIPPED": 4}
STATUS_NAMES = {code: name for name, code in STATUS_CODES.items()}
_LEAF = Btlog()  # a catalog behavior's leaf: its own result says


class BtlogError(ValueError):
    """A file that does not follow the FileLogger2 format."""


@dataclass(frozen=True)
class Transition:
    """One status change: microseconds since the log's first timestamp, the node's uid, the new status code."""

    usec: int
    uid: int
    status: int

    @property
    def status_name(self) -> str:
        return STATUS_NAMES.get(self.status, str(self.status))


def encode_transition(usec: int, uid: int, status: int) -> bytes:
    """The 9 bytes of one transition."""
    if not 0 <= usec < 1 << 48 or not 0 <= uid < 1 << 16 or not 0 <= status < 256:
        raise ValueError(f"a transition out of range: {usec} us, uid {uid}, status {status}")
    return usec.to_bytes(6, "little") + struct.pack("<HB", uid, status)


def decode_transition(data: bytes) -> Transition:
    return Transition(int.from_bytes(data[:6], "little"), *struct.unpack_from("<HB", data, 6))


# -- the transitions BehaviorTree.CPP logs ---------------------------------------------------------------------
class TransitionTracker:
    """BehaviorTree.CPP's status of every node, moved along by the nodes our runtime ticks; reports each change."""

    def __init__(self, mission: Any, report: Callable[[int, str], None]) -> None:
        self.report = report
        self.uids = {id(node): uid for uid, (_, node) in enumerate(mission.nodes, 1)}
        self.status = {uid: "IDLE" for uid in self.uids.values()}
        self.children: dict[int, list[Behaviour]] = {}
        self.root = mission.root
        self.mission_nodes = mission.nodes
        self.results: dict[int, str] = {}
        self.rules = {id(node): _rule(getattr(model_of(node), "type", "")) for _, node in mission.nodes}
        for _, node in mission.nodes:
            self.children[id(node)] = self._visible(node.children)

    def _visible(self, nodes: Iterable[Behaviour]) -> list[Behaviour]:
        found: list[Behaviour] = []
        for node in nodes:
            found.extend([node] if id(node) in self.uids else self._visible(node.children))
        return found

    def _set(self, node: Behaviour, status: str) -> None:
        uid = self.uids[id(node)]
        if self.status[uid] != status:
            self.status[uid] = status
            self.report(uid, status)

    def _reset(self, node: Behaviour) -> None:
        """BehaviorTree.CPP's ``haltChild``: a running node is halted (its children reset alike), then it is IDLE."""
        if self.status[self.uids[id(node)]] == "RUNNING":
            self._halt(node)
        self._set(node, "IDLE")

    def _halt(self, node: Behaviour) -> None:
        for child in self.children[id(node)]:
            self._reset(child)
        self._set(node, "IDLE")

    def ticked(self, visited: Iterable[tuple[Behaviour, str]]) -> None:
        """One tick of the tree: ``visited``, every node the tick yielded with the status it returned then."""
        self.results = {id(node): status for node, status in visited}
        if id(self.root) not in self.results:  # nothing was ticked
            return
        self._tick(self.root, set(self.results))
        if self.status[self.uids[id(self.root)]] in ("SUCCESS", "FAILURE"):  # Tree::tickRoot resets a completed root
            self._set(self.root, "IDLE")

    def halted(self) -> None:
        """``Tree::haltTree``: the root halted, then every node halted again, in pre-order."""
        self._halt(self.root)
        for _, node in self.mission_nodes:
            self._halt(node)

    def _tick(self, node: Behaviour, seen: set[int]) -> None:
        rule = self.rules[id(node)]  # how BT.CPP logs the node's kind (trees.runtime.kinds)
        uid = self.uids[id(node)]
        if rule.running == "tick" or (rule.running == "idle" and self.status[uid] == "IDLE"):
            self._set(node, "RUNNING")
        decorator = rule.resets_child
        children = self.children[id(node)]
        for index, child in enumerate(children):
            if id(child) not in seen:
                continue
            self._tick(child, seen)
            state = self.status[self.uids[id(child)]]
            if decorator and state != "RUNNING":
                self._reset(child)  # a decorator resets its child as soon as it completes
            if rule.other_branch and index == 0 and len(children) == 3 and state in ("SUCCESS", "FAILURE"):
                self._reset(children[2 if state == "SUCCESS" else 1])  # the other branch, before this one ticks
        result = self.results.get(id(node)) or status_name(node)
        if result == "IDLE":  # not ticked after all
            self._reset(node)
            return
        reactive = rule.halts_others
        first = 0
        if rule.keeps_succeeded and result == "FAILURE":  # it keeps the children that succeeded
            first = max((i for i, child in enumerate(children) if id(child) in seen), default=0)
        if rule.bare_condition and len(children) == 2 and result == "FAILURE" and id(children[1]) not in seen:
            first = len(children)  # a failed condition without an else: BT.CPP resets nothing
        for child in children[first:]:
            state = self.status[self.uids[id(child)]]
            if state == "IDLE":
                continue
            if (result != "RUNNING" or (reactive and state != "RUNNING")
                    or (state == "RUNNING" and id(child) not in seen and status_name(child) == "IDLE")):
                self._reset(child)  # completed (children reset), reactive, or a running child our runtime halted
        self._set(node, result)


def _rule(name: str) -> Btlog:
    kind = kind_of(name)
    return kind.btlog if kind is not None and kind.btlog is not None else _LEAF


# -- writing -------------------------------------------------------------------------------------------------
class BtlogWriter:
    """Writes ``mission``'s status transitions to ``path`` as they happen (each tick's flushed) until :meth:`close`.

    A file holds one tree: when a change in flight gives the tree other nodes, the writer goes on in the next file,
    ``NAME.change-K.btlog`` (K counts the changes), whose header is the changed tree."""

    def __init__(self, mission: Any, path: str | Path, catalog: Any = None, append: bool = False) -> None:
        """``append``: a resumed run goes on in the interrupted run's last file (the same tree, its changes made
        again; its times go on)."""
        if Path(path).suffix != ".btlog":
            raise ValueError(f"{path}: a FileLogger2 file's extension must be .btlog")
        self.mission = mission
        self.first_path = self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.catalog = catalog if catalog is not None else mission.engine.catalog
        self.changes = 0
        self._stale = False  # the tree changed since the file began
        self.incomplete: str | None = None  # why the file stopped short (a write error), None while whole
        self._lock = threading.Lock()
        self._fd: int | None = None
        if append:
            self._go_on()
        else:
            self._open()
        mission.observers.append(self.on_tick)
        getattr(mission, "restructured", []).append(self._restructured)

    def _open(self) -> None:
        self.start = self.mission.engine.now()
        self.first_timestamp_usec = time.time_ns() // 1000
        self.transitions = 0
        self._pending = bytearray()
        xml = tree_xml(self.mission, self.catalog).encode("utf-8")
        self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        self._write(MAGIC + bytes([PROTOCOL]) + struct.pack("<i", len(xml)) + xml +
                    struct.pack("<q", self.first_timestamp_usec))
        self.tracker = TransitionTracker(self.mission, self._record)

    def _go_on(self) -> None:
        """Go on in the last file of the interrupted run (``NAME.change-K.btlog`` for the highest K, else the first),
        after its last whole transition; a new file when there is none to go on in."""
        later = sorted((int(p.stem.rsplit("-", 1)[1]), p) for p in self.first_path.parent.glob(
            f"{self.first_path.stem}.change-*.btlog") if p.stem.rsplit("-", 1)[1].isdigit())
        if later:
            self.changes, self.path = later[-1]
        if not _whole_records(self.path):
            self._open()
            return
        self.start, self.first_timestamp_usec = 0.0, time.time_ns() // 1000
        self.transitions, self._pending = 0, bytearray()
        self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND)
        self.tracker = TransitionTracker(self.mission, self._record)

    def _restructured(self) -> None:
        """The tree was changed in flight: this file ends, the changed tree's begins at the next tick (several
        changes between two ticks make one file)."""
        self._stale = True

    def _next_file(self) -> None:
        self._stale = False
        with self._lock:
            fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)
        if self.incomplete is not None:
            return
        self.changes += 1
        self.path = self.first_path.with_name(f"{self.first_path.stem}.change-{self.changes}.btlog")
        try:
            self._open()
        except OSError as error:
            self.incomplete = error.strerror or str(error)
            logger.error("the tree log %s cannot be written (%s): the flight goes on", self.path, self.incomplete)

    def _record(self, uid: int, status: str) -> None:
        usec = max(0, round((self.mission.engine.now() - self.start) * 1e6))
        self._pending += encode_transition(usec, uid, STATUS_CODES[status])
        self.transitions += 1

    def on_tick(self, visited: list[Behaviour] | None) -> None:
        """The mission's observer: ``visited`` after a tick, None when the tree was halted."""
        if self._stale:
            self._next_file()
        if visited is None:
            self.tracker.halted()
        else:
            self.tracker.ticked(visited)
        data, self._pending = bytes(self._pending), bytearray()
        if data:
            self._write(data)

    def _write(self, data: bytes) -> None:
        with self._lock:
            if self._fd is None or self.incomplete is not None:
                return
            start = None
            try:
                start = os.lseek(self._fd, 0, os.SEEK_CUR)
                written = os.write(self._fd, data)
                while written < len(data):
                    written += os.write(self._fd, data[written:])
            except OSError as error:  # a full disk: cut back to the last whole record, write nothing more
                self.incomplete = error.strerror or str(error)
                if start is not None:
                    with contextlib.suppress(OSError):
                        os.ftruncate(self._fd, start)
                logger.error("the tree log %s cannot be written (%s): it stops here; the flight goes on",
                             self.path, self.incomplete)

    def close(self) -> None:
        if self.on_tick in self.mission.observers:
            self.mission.observers.remove(self.on_tick)
        if self._restructured in getattr(self.mission, "restructured", []):
            self.mission.restructured.remove(self._restructured)
        with self._lock:
            fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)


def _whole_records(path: Path) -> bool:
    """Cut a transition a killed process left half written off the end of ``path``; False when it has no whole
    header to go on after."""
    try:
        with open(path, "rb+") as file:
            head = file.read(len(MAGIC) + 5)
            if len(head) < len(MAGIC) + 5 or not head.startswith(MAGIC):
                return False
            header = len(MAGIC) + 5 + struct.unpack("<i", head[len(MAGIC) + 1:])[0] + 8
            size = file.seek(0, os.SEEK_END)
            if size < header:
                return False
            file.truncate(size - (size - header) % RECORD)
    except OSError:
        return False
    return True


# -- reading -------------------------------------------------------------------------------------------------
@dataclass
class Btlog:
    """A parsed ``.btlog``: the XML header, the first timestamp and the transitions."""

    xml: str
    first_timestamp_usec: int
    transitions: list[Transition] = field(default_factory=list)

    def nodes(self) -> dict[int, tuple[str, str]]:
        """uid -> (node type, name) of every node of the XML header (a SubTree's name: its ``_fullpath``)."""
        found: dict[int, tuple[str, str]] = {}
        for element in SafeElementTree.fromstring(self.xml).iter():
            if "_uid" in element.attrib:
                found[int(element.attrib["_uid"])] = (element.tag, element.get("name", element.get("_fullpath", "")))
        return found

    def subtrees(self) -> list[tuple[str, str]]:
        """(ID, _fullpath) of every tree instance, in the file's order."""
        document = SafeElementTree.fromstring(self.xml)
        return [(tree.get("ID", ""), tree.get("_fullpath", "")) for tree in document.findall("BehaviorTree")]


def read_btlog(path: str | Path) -> Btlog:
    """Parse a ``.btlog`` per the FileLogger2 format; a :class:`BtlogError` says where it does not follow it."""
    try:
        data = read_bytes(path, limit=1 << 30)  # a FIFO or a device is refused unread
    except InputError as exc:
        raise BtlogError(str(exc)) from None
    if not data.startswith(MAGIC):
        raise BtlogError(f"{path}: not a FileLogger2 file: it does not start with {MAGIC.decode()} "
                         "(files of BehaviorTree.CPP before 4.3 are not read)")
    header = len(MAGIC) + 1
    if len(data) < header + 4:
        raise BtlogError(f"{path}: {len(data)} bytes, too short for the XML size")
    if data[len(MAGIC)] != PROTOCOL:
        raise BtlogError(f"{path}: protocol {data[len(MAGIC)]}, only protocol {PROTOCOL} is known")
    (size,) = struct.unpack_from("<i", data, header)
    start = header + 4
    if size < 0 or start + size + 8 > len(data):
        raise BtlogError(f"{path}: the XML size {size} does not fit in the file ({len(data)} bytes)")
    try:
        xml = data[start:start + size].decode("utf-8")
        document = SafeElementTree.fromstring(xml)
    except UnicodeDecodeError as error:
        raise BtlogError(f"{path}: the tree XML is not UTF-8 (byte {error.start + start})") from None
    except ElementTree.ParseError as error:
        raise BtlogError(f"{path}: the tree XML does not parse: {error}") from None
    if document.tag != "root" or document.find("BehaviorTree") is None:
        raise BtlogError(f"{path}: the XML has no <root> with a <BehaviorTree>")
    (first,) = struct.unpack_from("<q", data, start + size)
    log = Btlog(xml, first)
    uids = set(log.nodes())
    body = data[start + size + 8:]
    if len(body) % RECORD:
        raise BtlogError(f"{path}: {len(body)} bytes of transitions, not a whole number of {RECORD}-byte records")
    for offset in range(0, len(body), RECORD):
        transition = decode_transition(body[offset:offset + RECORD])
        if transition.uid not in uids:
            raise BtlogError(f"{path}: transition {offset // RECORD} names uid {transition.uid}, not in the tree")
        if transition.status not in STATUS_NAMES:
            raise BtlogError(f"{path}: transition {offset // RECORD} has status {transition.status}")
        log.transitions.append(transition)
    return log
