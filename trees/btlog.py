"""Groot2 replay files (``.btlog``, BehaviorTree.CPP's FileLogger2 format) of tree missions: a writer that follows a
:class:`~aeroexec.trees.runner.TreeMission`'s node status events, and a reader that checks a file against the format.

The format, as BehaviorTree.CPP 4 documents it (``include/behaviortree_cpp/loggers/bt_file_logger_v2.h`` and
``src/loggers/bt_file_logger_v2.cpp``; the XML as ``WriteTreeToXML(tree, add_metadata=true, ...)`` writes it),
every number little-endian:

- 4 bytes: N, the size of the XML (int32);
- N bytes: the tree as XML: ``<root BTCPP_format="4">``, one ``<BehaviorTree ID=... _fullpath=...>`` per tree
  instance (the main tree first, then each SubTree's, in creation order; a ``<SubTree>`` element names its tree
  with ``ID`` and ``_fullpath`` and has no children), every node with a ``_uid`` attribute, then a
  ``<TreeNodesModel>`` of the node types that are not built into BehaviorTree.CPP;
- 8 bytes: the first timestamp (int64, microseconds since the Unix epoch);
- then 8 bytes per transition, a uint64 of bit fields from the least significant bit: 45 bits of microseconds
  since the first timestamp, 16 bits of node uid, 3 bits of the new status (IDLE 0, RUNNING 1, SUCCESS 2,
  FAILURE 3, SKIPPED 4).

Uids are the nodes' 1-based places in document order (subtrees expanded), which is how BehaviorTree.CPP numbers
nodes as it creates them and how ``TreeMission`` numbers its ``node_status`` events. Timestamps are engine time,
so a simulated run replays at its simulated pace.
"""

from __future__ import annotations

import os
import struct
import threading
import time
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import defusedxml.ElementTree as SafeElementTree
from aeroexec.trees.builder import model_of
from aeroexec.trees.groot import tree_nodes_model
from py_trees.behaviour import Behaviour

from aeroexec.limits import InputError, read_bytes

STATUS_CODES = {"IDLE": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3, "SKIPPED": 4}
STATUS_NAMES = {code: name for name, code in STATUS_CODES.items()}
TIMESTAMP_BITS, UID_BITS, STATUS_BITS = 45, 16, 3


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
    """The 8 bytes of one transition."""
    if not 0 <= usec < 1 << TIMESTAMP_BITS or not 0 <= uid < 1 << UID_BITS or not 0 <= status < 1 << STATUS_BITS:
        raise ValueError(f"a transition out of range: {usec} us, uid {uid}, status {status}")
    return struct.pack("<Q", usec | uid << TIMESTAMP_BITS | status << (TIMESTAMP_BITS + UID_BITS))


def decode_transition(data: bytes) -> Transition:
    (value,) = struct.unpack("<Q", data)
    return Transition(value & ((1 << TIMESTAMP_BITS) - 1), (value >> TIMESTAMP_BITS) & ((1 << UID_BITS) - 1),
                      value >> (TIMESTAMP_BITS + UID_BITS))


# -- the tree as XML -----------------------------------------------------------------------------------------
def tree_xml(mission: Any, catalog: Any = None) -> str:
    """The XML header of ``mission`` (a TreeMission): its trees with ``_uid`` attributes, and the node models."""
    uids = {id(node): uid for uid, (_, node) in enumerate(mission.nodes, 1)}
    root = ElementTree.Element("root", BTCPP_format="4")
    main = ElementTree.SubElement(root, "BehaviorTree", ID=mission.document.main, _fullpath="")
    used: set[str] = set()

    def add(node: Behaviour, parent: ElementTree.Element, path: str) -> None:
        if id(node) not in uids:  # hidden (a node wrapped by its preconditions): its children show instead
            for child in node.children:
                add(child, parent, path)
            return
        uid = uids[id(node)]
        model = model_of(node)
        kind = getattr(model, "type", type(node).__name__)
        ports = dict(getattr(model, "ports", {}))
        used.add(kind)
        if kind == "SubTree":
            tree_id = ports.pop("ID", "")
            name = node.name if node.name != "SubTree" else f"{tree_id}::{uid}"
            full = f"{path}/{name}" if path else name
            ElementTree.SubElement(parent, kind, ID=tree_id, _fullpath=full, _uid=str(uid), **ports)
            inner = ElementTree.SubElement(root, "BehaviorTree", ID=tree_id, _fullpath=full)
            for child in node.children:
                add(child, inner, full)
            return
        element = ElementTree.SubElement(parent, kind, name=node.name, _uid=str(uid), **ports)
        for child in node.children:
            add(child, element, path)

    add(mission.root, main, "")
    models = ElementTree.SubElement(root, "TreeNodesModel")
    if catalog is not None:
        palette = SafeElementTree.fromstring(tree_nodes_model(catalog))
        for model in palette.iter():
            if model.get("ID") in used:
                models.append(model)
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding="unicode")


# -- writing -------------------------------------------------------------------------------------------------
class BtlogWriter:
    """Writes ``mission``'s status transitions to ``path`` as they happen (each one flushed) until :meth:`close`."""

    def __init__(self, mission: Any, path: str | Path, catalog: Any = None) -> None:
        self.mission = mission
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.start = mission.engine.now()
        self.first_timestamp_usec = time.time_ns() // 1000
        self.transitions = 0
        self._lock = threading.Lock()
        xml = tree_xml(mission, catalog if catalog is not None else mission.engine.catalog).encode("utf-8")
        self._fd: int | None = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        self._write(struct.pack("<i", len(xml)) + xml + struct.pack("<q", self.first_timestamp_usec))
        self._unsubscribe = mission.engine.log.subscribe(self.on_event)

    def on_event(self, event: Any) -> None:
        if event.kind != "node_status" or "uid" not in event.data:
            return
        status = STATUS_CODES.get(str(event.data.get("new")))
        if status is None:
            return
        usec = max(0, round((event.time - self.start) * 1e6))
        self._write(encode_transition(usec, int(event.data["uid"]), status))
        self.transitions += 1

    def _write(self, data: bytes) -> None:
        with self._lock:
            if self._fd is None:
                return
            written = os.write(self._fd, data)
            while written < len(data):
                written += os.write(self._fd, data[written:])

    def close(self) -> None:
        self._unsubscribe()
        with self._lock:
            fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)


# -- reading -------------------------------------------------------------------------------------------------
@dataclass
class Btlog:
    """A parsed ``.btlog``: the XML header, the first timestamp and the transitions."""

    xml: str
    first_timestamp_usec: int
    transitions: list[Transition] = field(default_factory=list)

    def nodes(self) -> dict[int, tuple[str, str]]:
        """uid -> (node type, name) of every node of the XML header."""
        found: dict[int, tuple[str, str]] = {}
        for element in SafeElementTree.fromstring(self.xml).iter():
            if "_uid" in element.attrib:
                found[int(element.attrib["_uid"])] = (element.tag, element.get("name") or element.get("ID", ""))
        return found


def read_btlog(path: str | Path) -> Btlog:
    """Parse a ``.btlog`` per the FileLogger2 format; a :class:`BtlogError` says where it does not follow it."""
    try:
        data = read_bytes(path, limit=1 << 30)  # a FIFO or a device is refused unread
    except InputError as exc:
        raise BtlogError(str(exc)) from None
    if len(data) < 4:
        raise BtlogError(f"{path}: {len(data)} bytes, too short for the XML size")
    (size,) = struct.unpack_from("<i", data, 0)
    if size < 0 or 4 + size + 8 > len(data):
        raise BtlogError(f"{path}: the XML size {size} does not fit in the file ({len(data)} bytes)")
    try:
        xml = data[4:4 + size].decode("utf-8")
        document = SafeElementTree.fromstring(xml)
    except UnicodeDecodeError as error:
        raise BtlogError(f"{path}: the tree XML is not UTF-8 (byte {error.start + 4})") from None
    except ElementTree.ParseError as error:
        raise BtlogError(f"{path}: the tree XML does not parse: {error}") from None
    if document.tag != "root" or document.find("BehaviorTree") is None:
        raise BtlogError(f"{path}: the XML has no <root> with a <BehaviorTree>")
    (first,) = struct.unpack_from("<q", data, 4 + size)
    log = Btlog(xml, first)
    uids = set(log.nodes())
    body = data[4 + size + 8:]
    for offset in range(0, len(body) - len(body) % 8, 8):
        transition = decode_transition(body[offset:offset + 8])
        if transition.uid not in uids:
            raise BtlogError(f"{path}: transition {offset // 8} names uid {transition.uid}, not in the tree")
        if transition.status not in STATUS_NAMES:
            raise BtlogError(f"{path}: transition {offset // 8} has status {transition.status}")
        log.transitions.append(transition)
    return log
