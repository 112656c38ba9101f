"""BehaviorTree.CPP's Groot2 publisher protocol for a running tree mission, so Groot2 and its monitors attach.

ZeroMQ REP on ``port`` (default 1667) and PUB on ``port + 1``, bound to 127.0.0.1 unless a host is given. A request
is a 6-byte header (protocol byte, type letter, uint32 id) and an optional payload frame; a reply is the header
echoed with the tree's 16-byte UUID, then the payload, as ``groot2_protocol.h`` and ``groot2_publisher.cpp`` of
BehaviorTree.CPP 4.8-4.10 define them:

- ``T`` the tree as XML with ``_uid`` and ``_fullpath`` (:func:`~aeroexec.trees.groot.tree_xml.tree_xml`);
- ``S`` 3 bytes per node: uint16 uid, uint8 status (IDLE after a status is sent as 10 + that status);
- ``B`` the blackboards named in the payload (``Main;sub``) as msgpack ``{name: {key: value}}``;
- ``r`` recording of transitions ``start`` (reply: the start time in µs) / ``stop``; ``t`` the recorded
  transitions as 9-byte records (6-byte µs, uint16 uid, uint8 status), drained on read;
- ``D`` the hooks (none: ``[]``); ``A`` / ``X`` remove / disable every hook (there are none).

Breakpoints and node replacement (``I``, ``R``, ``U``) change how a flying drone's mission runs: they are refused
with an error reply, as BehaviorTree.CPP answers a request it cannot serve. Statuses come from the mission's
``node_status`` events on the engine's thread; the server thread never touches the tree.
"""

from __future__ import annotations

import logging
import struct
import threading
import time
import uuid
from collections import deque
from typing import Any

from aeroexec.extras import require

with require("groot"):
    import msgpack
    import zmq

logger = logging.getLogger(__name__)

DEFAULT_PORT = 1667
PROTOCOL = 2
STATUS_CODES = {"IDLE": 0, "INVALID": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3, "SKIPPED": 4}
MAX_TRANSITIONS = 1000  # BehaviorTree.CPP keeps at most this many unread transitions
BLACKBOARD_PERIOD = 0.2  # wall seconds between two copies of the blackboard, taken on the engine's thread
POLL_MS = 100


class GrootPublisherError(RuntimeError):
    """The publisher's ports cannot be bound."""


def _jsonable(value: Any) -> Any:
    if isinstance(value, bool | int | float | str) or value is None:
        return value
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    return str(value)


class GrootPublisher:
    """Serves one :class:`~aeroexec.trees.runtime.runner.TreeMission` to Groot2 clients until :meth:`close`."""

    def __init__(self, mission: Any, port: int = DEFAULT_PORT, host: str = "127.0.0.1", catalog: Any = None) -> None:
        from aeroexec.trees.groot.tree_xml import tree_xml

        self.mission, self.engine, self.catalog = mission, mission.engine, catalog
        self.xml = tree_xml(mission, catalog).encode()
        self.uuid = uuid.uuid4().bytes
        self._statuses = [0] * len(mission.nodes)  # by uid - 1, as BehaviorTree.CPP encodes them
        self._lock = threading.Lock()
        getattr(mission, "restructured", []).append(self._restructured)
        self._recording_since: float | None = None  # engine time
        self._transitions: deque[bytes] = deque(maxlen=MAX_TRANSITIONS)
        self._blackboard: dict[str, Any] = {}
        self._copied_at = 0.0
        self._context = zmq.Context.instance()
        self._server = self._context.socket(zmq.REP)
        self._publisher = self._context.socket(zmq.PUB)
        for sock in (self._server, self._publisher):
            sock.setsockopt(zmq.LINGER, 0)
        try:
            self._server.bind(f"tcp://{host}:{port}")
            self._publisher.bind(f"tcp://{host}:{port + 1}")
        except zmq.ZMQError as error:
            self._server.close()
            self._publisher.close()
            raise GrootPublisherError(f"the Groot2 publisher cannot use ports {port} and {port + 1} on {host}: "
                                      f"{error}") from None
        self.port = port
        self._unsubscribe = self.engine.log.subscribe(self._on_event)
        self.engine.tick_callbacks.append(self._copy_blackboard)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="aeroexec-groot2", daemon=True)
        self._thread.start()

    # -- on the engine's thread ---------------------------------------------------------------------
    def _on_event(self, event: Any) -> None:
        if event.kind != "node_status":
            return
        uid = int(event.data.get("uid", 0))
        if not 1 <= uid <= len(self._statuses):
            return
        new = STATUS_CODES.get(str(event.data.get("new")), 0)
        with self._lock:
            old = self._statuses[uid - 1]
            self._statuses[uid - 1] = 10 + (old % 10) if new == 0 and old % 10 else new
            if self._recording_since is not None:
                usec = max(0, int(round((event.time - self._recording_since) * 1e6)))
                self._transitions.append(usec.to_bytes(6, "little") + struct.pack("<HB", uid, new))

    def _copy_blackboard(self) -> None:
        if time.monotonic() - self._copied_at < BLACKBOARD_PERIOD:
            return
        self._copied_at = time.monotonic()
        board = self.mission.blackboard
        values = {key: _jsonable(board[key]) for key in list(board)}
        with self._lock:
            self._blackboard = values

    # -- on the server's thread ---------------------------------------------------------------------
    def _serve(self) -> None:
        poller = zmq.Poller()
        poller.register(self._server, zmq.POLLIN)
        while not self._stop.is_set():
            try:
                if not poller.poll(POLL_MS):
                    continue
                frames = self._server.recv_multipart()
                self._server.send_multipart(self.answer(frames))
            except zmq.ZMQError as error:
                if not self._stop.is_set():
                    logger.warning("the Groot2 publisher stops: %s", error)
                return

    def answer(self, frames: list[bytes]) -> list[bytes]:
        """The reply frames to one request's frames."""
        if not frames or len(frames[0]) != 6:
            return [b"error", b"wrong request header"]
        _, kind, request_id = struct.unpack("<BBI", frames[0])
        header = struct.pack("<BBI", PROTOCOL, kind, request_id) + self.uuid
        letter = chr(kind)
        payload = frames[1] if len(frames) > 1 else None
        if letter == "T":
            return [header, self.xml]
        if letter == "S":
            with self._lock:
                statuses = list(self._statuses)
            return [header, b"".join(struct.pack("<HB", uid, s) for uid, s in enumerate(statuses, 1))]
        if letter == "B":
            if payload is None:
                return [b"error", b"must be 2 parts message"]
            return [header, msgpack.packb(self._blackboards(payload.decode("utf-8", "replace")))]
        if letter == "r":
            return self._recording(header, payload)
        if letter == "t":
            with self._lock:
                records = b"".join(self._transitions)
                self._transitions.clear()
            return [header, records]
        if letter == "D":
            return [header, b"[]"]
        if letter in "AX":
            return [header]
        if letter in "IRU":
            return [b"error", b"breakpoints and node replacement are not supported by aeroexec: they would change "
                              b"how the drone's mission runs"]
        return [b"error", b"Request not recognized"]

    def _blackboards(self, names: str) -> dict[str, Any]:
        with self._lock:
            values = dict(self._blackboard)
        main = self.mission.document.main
        return {name: values for name in names.split(";") if name == main}

    def _recording(self, header: bytes, payload: bytes | None) -> list[bytes]:
        if payload == b"start":
            with self._lock:
                self._recording_since = self.engine.now()
                self._transitions.clear()
            return [header, str(int(time.time() * 1e6)).encode()]
        if payload == b"stop":
            with self._lock:
                self._recording_since = None
            return [header]
        return [b"error", b"must be start or stop"]

    def _restructured(self) -> None:
        """The tree was changed in flight: Groot2 gets the changed tree (a new uuid tells it to ask again)."""
        from aeroexec.trees.groot.tree_xml import tree_xml

        xml = tree_xml(self.mission, self.catalog).encode()
        with self._lock:
            self.xml, self.uuid = xml, uuid.uuid4().bytes
            self._statuses = [0] * len(self.mission.nodes)

    def close(self) -> None:
        """Stop serving; never hangs."""
        if self._restructured in getattr(self.mission, "restructured", []):
            self.mission.restructured.remove(self._restructured)
        self._stop.set()
        self._unsubscribe()
        if self._copy_blackboard in self.engine.tick_callbacks:
            self.engine.tick_callbacks.remove(self._copy_blackboard)
        self._thread.join(timeout=2.0)
        self._server.close(linger=0)
        self._publisher.close(linger=0)
