"""One process's place in a fleet: its drones' messages sent and the fleet's taken once per engine period, the table
of what it heard (:mod:`aeroexec.fleet.table`), one command queryable per local drone.

What a local drone says in a period is kept and put at the period's end (:meth:`FleetNode.exchange`) as one
``tick`` message on its own key (the fleet's router lets only its identity put there); what arrived from the fleet
waits in Zenoh's queue (never a Python callback per message) and is taken then too, local and remote messages
together, ordered by drone, so what a local drone hears at period k is what the process's drones said at period
k - 1, whatever the load. A local drone's messages never leave through Zenoh and come back. A fleet spread over worker
processes (:meth:`FleetNode.lockstep`) ends each period with a ``step`` message and takes every other worker's
ticks of the period before going on (:mod:`aeroexec.fleet.lockstep`), so its drones hear what they would hear in
one process.

Refused here, counted (one log line per sender and reason per interval, :mod:`~aeroexec.fleet.refusals`) and told to
the links for their event logs: malformed or foreign messages, a sender that is not in the fleet's roster, a
message on the keys of a drone of this process that this process did not send. Commands need the fleet's token (a
second factor: the operator's identity is checked by the router) and are answered from one thread, every drone's
at once; the answer of the process's first drone names the fleet's members it knows (``fleet``), so the operator
can name the drones that did not answer. A command carries an ``id``: the operator sends it through every router it
knows at once (:mod:`aeroexec.fleet.control`), and a copy that arrives by a second path is answered with the first
copy's result, never run twice.
"""

from __future__ import annotations

import hmac
import json
import logging
import operator
import queue
import threading
import time
from collections import OrderedDict
from collections.abc import Mapping
from typing import Any

from aeroexec.fleet import payloads
from aeroexec.fleet.access import Roster
from aeroexec.fleet.lockstep import HELLO, Lockstep
from aeroexec.fleet.payloads import VERSION, PayloadError, check_name, decode, encode, is_name, key, said
from aeroexec.fleet.refusals import MAX_KINDS, Refusals
from aeroexec.fleet.table import FleetTable

logger = logging.getLogger(__name__)

COMMAND_TIMEOUT = 5.0  # wall seconds a command waits for the drones' engines to run it
QUEUED = 1 << 16  # samples Zenoh keeps for the next period's end (then it waits: back-pressure, nothing lost)
MAX_ID = 64  # characters of a command's id
REMEMBERED = 1024  # commands remembered by their id, so a copy arriving by another path is not run again
_drone = operator.itemgetter(0)  # a message's drone: what a period's messages are ordered by


def qos(lockstep: bool = False) -> dict[str, Any]:
    """Zenoh QoS of a drone's messages: never block the engine (DROP when congested), unless the fleet is in
    lockstep, where every period must arrive (BLOCK: simulated time waits); only for other sessions."""
    import zenoh

    congestion = zenoh.CongestionControl.BLOCK if lockstep else zenoh.CongestionControl.DROP
    return {"congestion_control": congestion, "priority": zenoh.Priority.DATA,
            "allowed_destination": zenoh.Locality.REMOTE}


def _direct(callback: Any) -> Any:
    """``callback`` run on the thread that delivers the sample (Zenoh's)."""
    import zenoh

    return zenoh.handlers.Callback(callback, indirect=False)


def _queued() -> Any:
    import zenoh

    return zenoh.handlers.FifoChannel(QUEUED)


def _remote() -> Any:
    import zenoh

    return zenoh.Locality.REMOTE


class FleetNode:
    """The local drones of ``fleet`` on one Zenoh ``session``: their messages out, the fleet's in, commands.

    ``roster``: the fleet's members (a sender outside it is refused), who speaks for whom and what each shares;
    ``sessions``: the session of each local drone that speaks with an identity of its own (the others use
    ``session``); ``local``: the drones this process flies, known before they join (a message on their keys is
    theirs only). Whoever drives the local engines calls :meth:`exchange` at the end of each period and sets
    :attr:`driven`; otherwise each link exchanges at the end of its own update (a drone alone in its process)."""

    def __init__(self, session: Any, fleet: str, token: str, roster: Roster | None = None,
                 sessions: Mapping[str, Any] | None = None, local: tuple[str, ...] = ()) -> None:
        self.session, self.fleet, self.token = session, check_name(fleet, "the fleet name"), token
        self.roster = roster
        self.sessions = dict(sessions or {})
        self.local = set(local)
        self.links: dict[str, Any] = {}
        self.driven = False
        self.refusals = Refusals(fleet)
        self.table = FleetTable(lambda sender, reason, example, what: self.refuse(sender, reason, example, what))
        self._kinds: list[tuple[str, str, str]] = []  # every local drone hears of these refusals, even drones to come
        self._said: list[tuple[str, str, dict[str, Any]]] = []  # what the local drones said this period
        self._publishers: dict[tuple[str, str], Any] = {}
        self._queryables: dict[str, Any] = {}
        self._lock = threading.Lock()
        self._answers: queue.Queue[tuple[Any, str, str, Any, float, float | None] | None] = queue.Queue()
        #: (drone, command id) -> (its ticket, seconds it took to arrive, its deadline): the commands run, by id
        self._commands: OrderedDict[tuple[str, str], tuple[Any, float | None, float]] = OrderedDict()
        self._commanding = threading.Lock()  # held while a command is looked up by its id and submitted
        self._answering = threading.Thread(target=self._answer, name="aeroexec-fleet-commands", daemon=True)
        self._answering.start()
        self._closed = False
        self._lockstep: Lockstep | None = None
        self._hello: set[str] = set()  # the other workers heard while meeting
        self._early: list[tuple[str, str, dict[str, Any]]] = []  # what drones of their own said while meeting
        self._early_outside: set[str] = set()
        remote = _remote()
        self._queue = session.declare_subscriber(f"aeroexec/{fleet}/**", _queued(), allowed_origin=remote)

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
        self.local.add(link.name)
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

    def say(self, drone: str, topic: str, **fields: Any) -> None:
        """Keep one message of ``drone`` for the end of the period (telemetry, events, beliefs, broadcast)."""
        with self._lock:
            self._said.append((drone, topic, fields))

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

    # -- the end of a period (the engines' thread) -------------------------------------------------------------------
    def exchange(self, now: float, ended: bool = False) -> bool:
        """Send what the local drones said this period, take what the fleet said (in lockstep: every other worker's
        messages of the period, waited for), and tell the local links what changed. ``ended``: every local flight
        has ended. False when the fleet's flights have all ended (here and, in lockstep, in every worker)."""
        with self._lock:
            said, self._said = self._said, []
        lockstep = self._lockstep
        period = lockstep.period if lockstep is not None else None
        ticks = self._send(said, period)
        heard, outside = self._take()
        if self._early:
            heard[:0], self._early = self._early, []
            outside |= self._early_outside
        if lockstep is not None:
            self._put(lockstep.me, payloads.step(lockstep.me, lockstep.period, ticks, ended), "step")
            self._wait(heard, outside)
            heard.extend(lockstep.take(lockstep.period))
        messages = said + heard
        messages.sort(key=_drone)  # stable: each drone's messages stay in the order it said them
        news = self.table.take(messages, now, outside)
        if news:  # most periods nothing changed: no link has anything to hear
            for link in list(self.links.values()):
                link.hear(news)
        self.refusals.flush()
        return not (ended and (lockstep is None or lockstep.everyone_ended))

    # -- worker processes ----------------------------------------------------------------------------------------------
    def lockstep(self, me: str, peers: Mapping[str, Any], patience: float | None = None) -> Lockstep:
        """Fly in lockstep with the other workers ``peers`` (each one's first drone -> the drones it flies); ``me``:
        this worker's first drone. Call before :meth:`meet`."""
        self._lockstep = Lockstep(me, peers) if patience is None else Lockstep(me, peers, patience)
        return self._lockstep

    @property
    def in_lockstep(self) -> Lockstep | None:
        """The lockstep with the other workers, if this process is one of several."""
        return self._lockstep

    def meet(self, timeout: float, stop: threading.Event | None = None) -> bool:
        """Say hello until every other worker has heard this one and said so (True), or ``timeout`` wall seconds
        passed or ``stop`` was set (False)."""
        lockstep = self._lockstep
        if lockstep is None:
            return True
        deadline = time.monotonic() + timeout
        while True:
            self._put(lockstep.me, payloads.step(lockstep.me, HELLO, 0, False, sorted(self._hello)), "step")
            heard, outside = self._take()
            self._early.extend(heard)  # drones of processes of their own: heard at the first period
            self._early_outside |= outside
            if lockstep.met(self._hello):
                self._put(lockstep.me, payloads.step(lockstep.me, HELLO, 0, False, sorted(self._hello)), "step")
                return True
            if time.monotonic() > deadline or (stop is not None and stop.is_set()):
                return False
            time.sleep(0.05)

    def _wait(self, heard: list[tuple[str, str, dict[str, Any]]], outside: set[str]) -> None:
        """Take what arrives until every other worker's ticks of this period are here (or it is given up)."""
        lockstep = self._lockstep
        period = lockstep.period
        pause, deadline = 0.00005, None
        while missing := lockstep.missing(period):
            if deadline is None:
                deadline = time.monotonic() + lockstep.patience
            elif time.monotonic() > deadline:
                lockstep.give_up(missing)
                return
            time.sleep(pause)
            pause = min(2 * pause, 0.002)
            more, more_outside = self._take()
            heard.extend(more)
            outside |= more_outside

    def _send(self, said: list[tuple[str, str, dict[str, Any]]], period: int | None = None) -> int:
        """Put each local drone's messages as one tick; how many ticks were put."""
        if self._closed:
            return 0
        by_drone: dict[str, list[list[Any]]] = {}
        for drone, topic, fields in said:
            by_drone.setdefault(drone, []).append([topic, fields])
        for drone, messages in by_drone.items():  # each stamped as it is put: the link's latency, put -> arrival
            self._put(drone, payloads.tick(drone, messages, time.time(), period))
        return len(by_drone)

    def _put(self, drone: str, payload: bytes, topic: str = "tick") -> None:
        try:
            publisher = self._publishers.get((drone, topic))
            if publisher is None:
                session = self.sessions.get(drone, self.session)
                publisher = session.declare_publisher(key(self.fleet, drone, topic),
                                                      **qos(self._lockstep is not None))
                self._publishers[drone, topic] = publisher
            publisher.put(payload)
        except Exception as error:  # a closed session or a full queue: the drone flies on
            logger.debug("fleet %s: %s's %s not sent: %s", self.fleet, drone, topic, error)

    def _take(self) -> tuple[list[tuple[str, str, dict[str, Any]]], set[str]]:
        """What arrived from the fleet, checked; and its drones (they fly outside this process, on their own
        time). In lockstep, the other workers' ticks and steps go to their periods."""
        heard: list[tuple[str, str, dict[str, Any]]] = []
        outside: set[str] = set()
        lockstep = self._lockstep
        while (sample := self._queue.try_recv()) is not None:
            key_expr = str(sample.key_expr)
            try:
                drone, topic, message = decode(key_expr, bytes(sample.payload), self.fleet)
                if topic == "command":
                    continue  # commands are queries
                if topic == "step":
                    if lockstep is None or not lockstep.is_peer(drone):
                        raise PayloadError(f"{key_expr}: a step of {drone}, which is no worker of this fleet's",
                                           "a step of no worker of the fleet's")
                    period, ticks, ended, hello = payloads.stepped(message, key_expr)
                    if period == HELLO:
                        self._hello.add(drone)
                    lockstep.step(drone, period, ticks, ended, hello)
                    continue
                messages = said(message, key_expr)
                if lockstep is not None and lockstep.owns(drone):
                    if self._genuine(drone):
                        lockstep.tick(drone, payloads.period_of(message, key_expr),
                                      [(drone, topic, fields) for topic, fields in messages])
                    continue
            except PayloadError as error:
                parts = key_expr.split("/")
                self.refuse(parts[2] if len(parts) > 2 and is_name(parts[2]) else key_expr, error.reason, str(error))
                continue
            if not self._genuine(drone):
                continue
            outside.add(drone)
            heard.extend((drone, topic, fields) for topic, fields in messages)
        return heard, outside

    # -- Zenoh's threads -----------------------------------------------------------------------------------------------
    def _genuine(self, drone: str) -> bool:
        """False (the message refused) when its drone is no member, or flies in this process."""
        if self.roster is not None and drone not in self.roster.drones:
            self.refuse(drone, "not a fleet member")
            return False
        if drone in self.local:
            if drone not in self.sessions:
                self.refuse(drone, f"not said by {drone}, which flies in this process (someone else on its keys)")
            return False  # else (a drone with a session of its own) it came back through the router
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
        sent = request.get("sent")  # the operator's wall clock: how long the command took to reach this drone
        reached = round(time.time() - sent, 3) if isinstance(sent, (int, float)) and not isinstance(sent, bool) \
            else None
        ident = request.get("id")
        with self._commanding:  # two copies by two paths may come at once, on two of Zenoh's threads: one runs
            first = self._commands.get((drone, ident)) if isinstance(ident, str) and ident else None
            if first is not None:  # the same command by another path: answered with what the first copy did
                ticket, reached, deadline = first
            else:
                ticket = link.submit(request["command"], request.get("argument", ""))
                deadline = time.monotonic() + COMMAND_TIMEOUT
                if isinstance(ident, str) and ident:
                    self._commands[(drone, ident)] = (ticket, reached, deadline)
                    while len(self._commands) > REMEMBERED:
                        self._commands.popitem(last=False)
        self._answers.put((query, drone, request["command"], ticket, deadline, reached))

    def _request(self, query: Any) -> dict[str, Any]:
        try:
            request = json.loads(bytes(query.payload)) if query.payload is not None else None
        except (ValueError, UnicodeDecodeError, RecursionError):
            request = None
        if not isinstance(request, dict) or request.get("v") != VERSION or not isinstance(request.get("command"), str):
            raise PayloadError(f"not a fleet command (expected JSON {{v: {VERSION}, token, command, argument}})",
                               "not a fleet command")
        if not hmac.compare_digest(str(request.get("token", "")).encode(), self.token.encode()):
            raise PayloadError("wrong token: the fleet's token is in its output folder's fleet.json", "wrong token")
        if not isinstance(request.get("argument", ""), str):
            raise PayloadError("the command's argument must be text", "not a fleet command")
        if not isinstance(request.get("id", ""), str) or len(request.get("id", "")) > MAX_ID:
            raise PayloadError(f"the command's id must be text of at most {MAX_ID} characters", "not a fleet command")
        return request

    def _answer(self) -> None:
        """Reply to each command once its drone's engine ran it (or it timed out); the tickets run side by side."""
        while (item := self._answers.get()) is not None:
            query, name, command, ticket, deadline, reached = item
            result = ticket.wait(max(0.0, deadline - time.monotonic()))
            if result is None:
                answer = {"ok": False, "error": f"{name} did not run the command within {COMMAND_TIMEOUT:g} s"}
            else:
                answer = {"ok": result.ok, "message": result.message,  # a mission change's items and problems
                          **{k: result.data[k] for k in ("items", "problems") if k in result.data}}
                if command == "status":
                    answer["status"] = result.data
                    answer["silent"] = sorted(getattr(self.links.get(name), "silent", ()))
            if reached is not None:
                answer["reached"] = reached
            with self._lock:
                first = min(self.links, default=name)
            if name == first:  # one drone per process says who the operator should hear
                answer["fleet"] = self.members()
            try:
                with query:
                    query.reply(key(self.fleet, name, "command"), encode(name, **answer))
            except Exception as error:  # the session closed meanwhile
                logger.debug("fleet %s: the answer of %s was not sent: %s", self.fleet, name, error)

    def members(self) -> list[str]:
        """The fleet's drones as this process knows them: its roster, else its own drones and those it heard."""
        if self.roster is not None:
            return sorted(self.roster.drones)
        with self._lock:
            here = self.local | set(self.links)
        return sorted(here | set(self.table.heard.copy()))

    def close(self) -> None:
        """Stop hearing the fleet, the local drones' last words sent (the sessions are the caller's to close)."""
        if self._closed:
            return
        with self._lock:
            said, self._said = self._said, []
        self._send(said, self._lockstep.period if self._lockstep else None)  # the local drones' last words
        self._closed = True
        self._answers.put(None)
        # joined to its end: the commands waiting are answered, at most COMMAND_TIMEOUT after they came (a thread
        # still replying inside Zenoh when the interpreter finalizes is ended there, and the process aborts)
        self._answering.join()
        for entity in (self._queue, *self._queryables.values(), *self._publishers.values()):
            _undeclare(entity, self.fleet)
        self.refusals.flush(final=True)


def _undeclare(entity: Any, fleet: str) -> None:
    try:
        entity.undeclare()
    except Exception as error:
        logger.debug("fleet %s: undeclare failed: %s", fleet, error)
