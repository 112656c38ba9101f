"""One process's place in a fleet: one Zenoh session, one subscriber for the fleet's keys, one queryable for the
operator's commands, shared by every local drone's :class:`~aeroexec.fleet.link.FleetLink`.

Samples are decoded once here and handed to the links' inboxes; malformed or foreign ones are logged and
dropped. Commands need the fleet's token.
"""

from __future__ import annotations

import hmac
import logging
import statistics
import threading
import time
from typing import Any

from aeroexec.fleet.payloads import PayloadError, check_name, decode, encode, key

logger = logging.getLogger(__name__)

COMMAND_TIMEOUT = 5.0  # wall seconds a command waits for the drones' engines to run it
SILENT_AFTER = 2.0  # wall seconds without telemetry after which a drone is silent
_LATENCY_SAMPLES = 100_000


def qos(topic: str) -> dict[str, Any]:
    """Zenoh QoS of a topic: never block the engine (DROP when congested); a broadcast goes first and alone."""
    import zenoh

    if topic == "broadcast":
        return {"congestion_control": zenoh.CongestionControl.DROP, "priority": zenoh.Priority.DATA_HIGH,
                "express": True}
    return {"congestion_control": zenoh.CongestionControl.DROP, "priority": zenoh.Priority.DATA}


class FleetNode:
    """The local drones of ``fleet`` on one Zenoh ``session``: decoding, fan-out, commands, who was heard when."""

    def __init__(self, session: Any, fleet: str, token: str) -> None:
        self.session, self.fleet, self.token = session, check_name(fleet, "the fleet name"), token
        self.links: dict[str, Any] = {}
        self.last_heard: dict[str, float] = {}  # drone -> time.monotonic() of its last telemetry
        self.status: dict[str, dict[str, Any]] = {}  # drone -> its last telemetry
        self.latencies: list[float] = []  # s, telemetry publish -> receive (same-machine clocks)
        self.dropped = 0
        self._publishers: dict[tuple[str, str], Any] = {}
        self._lock = threading.Lock()
        self._closed = False
        self._subscriber = session.declare_subscriber(f"aeroexec/{fleet}/**", self._on_sample)
        self._queryable = session.declare_queryable(key(fleet, "*", "command"), self._on_query)

    # -- local drones --------------------------------------------------------------------------
    def attach(self, link: Any) -> None:
        with self._lock:
            if link.name in self.links:
                raise ValueError(f"two drones are called {link.name} in fleet {self.fleet}")
            self.links[link.name] = link

    def detach(self, name: str) -> None:
        with self._lock:
            self.links.pop(name, None)

    def publish(self, drone: str, topic: str, **fields: Any) -> None:
        """Put one message of ``drone`` on its ``topic`` key (QoS: DATA priority, DROP when congested)."""
        if self._closed:
            return
        try:
            publisher = self._publishers.get((drone, topic))
            if publisher is None:
                publisher = self.session.declare_publisher(key(self.fleet, drone, topic), **qos(topic))
                self._publishers[(drone, topic)] = publisher
            publisher.put(encode(drone, **fields))
        except Exception as error:  # a closed session or a full queue: the drone flies on
            logger.debug("fleet %s: %s/%s not sent: %s", self.fleet, drone, topic, error)

    def heard(self) -> dict[str, float]:
        with self._lock:
            return dict(self.last_heard)

    def latency(self) -> tuple[float, float, int]:
        """Median and 99th percentile (s) of telemetry publish -> receive, and how many samples."""
        with self._lock:
            samples = sorted(self.latencies)
        if not samples:
            return float("nan"), float("nan"), 0
        return statistics.median(samples), samples[min(len(samples) - 1, int(0.99 * len(samples)))], len(samples)

    # -- Zenoh's threads -----------------------------------------------------------------------
    def _on_sample(self, sample: Any) -> None:
        received = time.time()
        try:
            drone, topic, message = decode(str(sample.key_expr), bytes(sample.payload), self.fleet)
        except PayloadError as error:
            self.dropped += 1
            logger.warning("fleet %s: dropped a message: %s", self.fleet, error)
            return
        if topic == "command":
            return
        if topic == "telemetry":
            with self._lock:
                self.last_heard[drone] = time.monotonic()
                self.status[drone] = message
                sent = message.get("sent")
                if isinstance(sent, float) and len(self.latencies) < _LATENCY_SAMPLES:
                    self.latencies.append(received - sent)
        with self._lock:
            links = [link for name, link in self.links.items() if name != drone]
        for link in links:
            try:
                link.post(drone, topic, message)
            except Exception:
                logger.exception("fleet %s: %s could not take a message from %s", self.fleet, link.name, drone)

    def _on_query(self, query: Any) -> None:
        with query:
            try:
                request, targets = self._request(query)
            except PayloadError as error:
                logger.warning("fleet %s: refused a command: %s", self.fleet, error)
                query.reply_err(encode("fleet", ok=False, error=str(error)))
                return
            tickets = [(name, link.submit(request["command"], request.get("argument", ""))) for name, link in targets]
            deadline = time.monotonic() + COMMAND_TIMEOUT
            for name, ticket in tickets:
                result = ticket.wait(max(0.0, deadline - time.monotonic()))
                if result is None:
                    answer = {"ok": False, "error": f"{name} did not run the command within {COMMAND_TIMEOUT:g} s"}
                else:
                    answer = {"ok": result.ok, "message": result.message,
                              **{k: result.data[k] for k in ("items", "problems") if k in result.data}}
                    if request["command"] == "status":
                        answer["status"] = result.data
                        answer["silent"] = sorted(getattr(self.links.get(name), "silent", ()))
                query.reply(key(self.fleet, name, "command"), encode(name, **answer))

    def _request(self, query: Any) -> tuple[dict[str, Any], list[tuple[str, Any]]]:
        import json

        try:
            request = json.loads(bytes(query.payload)) if query.payload is not None else None
        except (ValueError, UnicodeDecodeError):
            request = None
        if not isinstance(request, dict) or request.get("v") != 1 or not isinstance(request.get("command"), str):
            raise PayloadError("not a fleet command (expected JSON {v: 1, token, command, argument})")
        if not hmac.compare_digest(str(request.get("token", "")).encode(), self.token.encode()):
            raise PayloadError("wrong token: the fleet's token is in its output folder's fleet.json")
        if not isinstance(request.get("argument", ""), str):
            raise PayloadError("the command's argument must be text")
        import zenoh

        asked = zenoh.KeyExpr(str(query.key_expr))
        with self._lock:
            targets = [(n, link) for n, link in sorted(self.links.items())
                       if asked.intersects(zenoh.KeyExpr(key(self.fleet, n, "command")))]
        return request, targets

    def close(self) -> None:
        """Stop hearing the fleet (the session is the caller's to close)."""
        if self._closed:
            return
        self._closed = True
        for entity in (self._subscriber, self._queryable, *self._publishers.values()):
            try:
                entity.undeclare()
            except Exception as error:
                logger.debug("fleet %s: undeclare failed: %s", self.fleet, error)
