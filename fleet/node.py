"""One process's place in a fleet: one subscriber for the fleet's keys and one command queryable per local drone,
shared by every local drone's :class:`~aeroexec.fleet.link.FleetLink`.

Samples are decoded once here and handed to the links' inboxes. Refused here, counted (one log line per sender and
reason per interval, :mod:`~aeroexec.fleet.refusals`) and told to the links for their event logs: malformed or
foreign messages, a sender that is not in the fleet's roster, a message on the keys of a drone of this process
that this process did not send. Local samples are delivered on the publishing thread (Zenoh's direct callback), so a
fleet in one process hears its own drones in the same order every run. Commands need the fleet's token (a second
factor: the operator's identity is checked by the router) and are answered from one thread, every drone's at once.
"""

from __future__ import annotations

import hmac
import json
import logging
import queue
import statistics
import threading
import time
from collections.abc import Mapping
from typing import Any

from aeroexec.fleet.access import Roster
from aeroexec.fleet.payloads import PayloadError, check_name, decode, encode, is_name, key, vector
from aeroexec.fleet.refusals import MAX_KINDS, Refusals

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


def _direct(callback: Any) -> Any:
    """``callback`` run on the thread that delivers the sample (Zenoh's, or the local publisher's)."""
    import zenoh

    return zenoh.handlers.Callback(callback, indirect=False)


class FleetNode:
    """The local drones of ``fleet`` on one Zenoh ``session``: decoding, fan-out, commands, who was heard when.

    ``roster``: the fleet's members (a sender outside it is refused) and what each shares; ``sessions``: the
    session of each local drone that speaks with an identity of its own (the others use ``session``); ``local``:
    the drones this process flies, known before they join (a message on their keys is theirs only)."""

    def __init__(self, session: Any, fleet: str, token: str, roster: Roster | None = None,
                 sessions: Mapping[str, Any] | None = None, local: tuple[str, ...] = ()) -> None:
        self.session, self.fleet, self.token = session, check_name(fleet, "the fleet name"), token
        self.roster = roster
        self.sessions = dict(sessions or {})
        self.local = set(local)
        self.links: dict[str, Any] = {}
        self.last_heard: dict[str, float] = {}  # drone -> time.monotonic() of its last telemetry
        self.status: dict[str, dict[str, Any]] = {}  # drone -> its last telemetry
        self.latencies: list[float] = []  # s, telemetry publish -> receive (same-machine clocks)
        self.refusals = Refusals(fleet)
        self._kinds: list[tuple[str, str, str]] = []  # every local drone hears of these refusals, even drones to come
        self._publishers: dict[tuple[str, str], Any] = {}
        self._queryables: dict[str, Any] = {}
        self._lock = threading.Lock()
        self._speaking = threading.local()  # the local drone whose message this thread is publishing
        self._answers: queue.Queue[tuple[Any, str, str, Any, float] | None] = queue.Queue()
        self._answering = threading.Thread(target=self._answer, name="aeroexec-fleet-commands", daemon=True)
        self._answering.start()
        self._closed = False
        self._subscriber = session.declare_subscriber(f"aeroexec/{fleet}/**", _direct(self._on_sample))

    @property
    def dropped(self) -> int:
        """How many messages and beliefs were refused."""
        return self.refusals.total

    # -- local drones --------------------------------------------------------------------------
    def attach(self, link: Any) -> None:
        with self._lock:
            if link.name in self.links:
                raise ValueError(f"two drones are called {link.name} in fleet {self.fleet}")
            self.links[link.name] = link
            kinds = list(self._kinds)
        for sender, reason, example in kinds:
            link.refused(sender, reason, example)
        session = self.sessions.get(link.name, self.session)
        self._queryables[link.name] = session.declare_queryable(
            key(self.fleet, link.name, "command"), _direct(lambda query: self._on_query(link.name, query)))

    def detach(self, name: str) -> None:
        with self._lock:
            self.links.pop(name, None)
        queryable = self._queryables.pop(name, None)
        if queryable is not None:
            _undeclare(queryable, self.fleet)

    def publish(self, drone: str, topic: str, **fields: Any) -> None:
        """Put one message of ``drone`` on its ``topic`` key (QoS: DATA priority, DROP when congested)."""
        if self._closed:
            return
        self._speaking.drone = drone
        try:
            publisher = self._publishers.get((drone, topic))
            if publisher is None:
                session = self.sessions.get(drone, self.session)
                publisher = session.declare_publisher(key(self.fleet, drone, topic), **qos(topic))
                self._publishers[(drone, topic)] = publisher
            publisher.put(encode(drone, **fields))
        except Exception as error:  # a closed session or a full queue: the drone flies on
            logger.debug("fleet %s: %s/%s not sent: %s", self.fleet, drone, topic, error)
        finally:
            self._speaking.drone = None

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

    def refuse(self, sender: str, reason: str, example: str = "", what: str = "message", everyone: bool = True) -> None:
        """Count a refusal of ``sender``'s message (or belief); the first of a kind goes to every local drone's event
        log unless ``everyone`` is False (a link refusing on its own records its event itself)."""
        if self.refusals.refuse(sender, reason, example, what) and everyone:
            with self._lock:
                links = list(self.links.values())
                if len(self._kinds) < MAX_KINDS:
                    self._kinds.append((sender, reason, example))
            for link in links:
                link.refused(sender, reason, example)

    # -- Zenoh's threads (and the local publisher's) ---------------------------------------------------------------
    def _on_sample(self, sample: Any) -> None:
        received = time.time()
        key_expr = str(sample.key_expr)
        try:
            drone, topic, message = decode(key_expr, bytes(sample.payload), self.fleet)
        except PayloadError as error:
            parts = key_expr.split("/")
            self.refuse(parts[2] if len(parts) > 2 and is_name(parts[2]) else key_expr, error.reason, str(error))
            return
        if not self._genuine(drone, topic):
            return
        if topic == "telemetry":
            try:
                vector(message.get("position"))
            except PayloadError as error:  # a heartbeat that says nothing: not heard
                self.refuse(drone, f"telemetry: {error.reason}", str(error))
                return
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

    def _genuine(self, drone: str, topic: str) -> bool:
        """False (the sample refused) when the sender is no member, or a local drone this process did not hear say
        it; a command put as a message is ignored."""
        if topic == "command":
            self.refuse(drone, "a command put as a message (commands are queries)")
            return False
        if self.roster is not None and drone not in self.roster.drones:
            self.refuse(drone, "not a fleet member")
            return False
        if (drone in self.local or drone in self.links) and drone not in self.sessions \
                and getattr(self._speaking, "drone", None) != drone:
            self.refuse(drone, f"not said by {drone}, which flies in this process (someone else on its keys)")
            return False
        return True

    def _on_query(self, drone: str, query: Any) -> None:
        try:
            request = self._request(query)
        except PayloadError as error:
            self.refuse("an operator", error.reason, f"{error} (asking {drone})")
            with query:
                query.reply_err(encode("fleet", ok=False, error=str(error)))
            return
        link = self.links.get(drone)
        if link is None:
            return
        ticket = link.submit(request["command"], request.get("argument", ""))
        self._answers.put((query, drone, request["command"], ticket, time.monotonic() + COMMAND_TIMEOUT))

    def _request(self, query: Any) -> dict[str, Any]:
        try:
            request = json.loads(bytes(query.payload)) if query.payload is not None else None
        except (ValueError, UnicodeDecodeError, RecursionError):
            request = None
        if not isinstance(request, dict) or request.get("v") != 1 or not isinstance(request.get("command"), str):
            raise PayloadError("not a fleet command (expected JSON {v: 1, token, command, argument})",
                               "not a fleet command")
        if not hmac.compare_digest(str(request.get("token", "")).encode(), self.token.encode()):
            raise PayloadError("wrong token: the fleet's token is in its output folder's fleet.json", "wrong token")
        if not isinstance(request.get("argument", ""), str):
            raise PayloadError("the command's argument must be text", "not a fleet command")
        return request

    def _answer(self) -> None:
        """Reply to each command once its drone's engine ran it (or it timed out); the tickets run side by side."""
        while (item := self._answers.get()) is not None:
            query, name, command, ticket, deadline = item
            result = ticket.wait(max(0.0, deadline - time.monotonic()))
            if result is None:
                answer = {"ok": False, "error": f"{name} did not run the command within {COMMAND_TIMEOUT:g} s"}
            else:
                answer = {"ok": result.ok, "message": result.message,  # a mission change's items and problems
                          **{k: result.data[k] for k in ("items", "problems") if k in result.data}}
                if command == "status":
                    answer["status"] = result.data
                    answer["silent"] = sorted(getattr(self.links.get(name), "silent", ()))
            try:
                with query:
                    query.reply(key(self.fleet, name, "command"), encode(name, **answer))
            except Exception as error:  # the session closed meanwhile
                logger.debug("fleet %s: the answer of %s was not sent: %s", self.fleet, name, error)

    def close(self) -> None:
        """Stop hearing the fleet (the sessions are the caller's to close)."""
        if self._closed:
            return
        self._closed = True
        self._answers.put(None)
        self._answering.join(1.0)  # an answer its engine will not give any more is not waited for
        for entity in (self._subscriber, *self._queryables.values(), *self._publishers.values()):
            _undeclare(entity, self.fleet)
        self.refusals.flush(final=True)


def _undeclare(entity: Any, fleet: str) -> None:
    try:
        entity.undeclare()
    except Exception as error:
        logger.debug("fleet %s: undeclare failed: %s", fleet, error)
