"""One drone's fleet link: what its engine tells the fleet and what it hears of the others, on its own tick.

Published (on the engine's thread): telemetry at ``telemetry_rate`` Hz of engine time (position, velocity, yaw,
battery, flight state, mission, active behaviors; also the drone's heartbeat), the engine's events (those of
a tick together, in one message), and
the beliefs of the ``share`` predicates (``self`` as written) once a second and when they change.
Heard (queued by the :class:`~aeroexec.fleet.node.FleetNode`, applied here): ``position(dN, (x, y, z))`` from
telemetry; shared beliefs with ``self`` replaced by the sender; BROADCAST_MESSAGE as ``message(dN, Text)``
while this drone's SOCIAL_COMMUNICATION capability runs. What a drone heard from another expires
``persistence`` seconds (wall time) after it was last said (a message: after its sender was last heard);
a drone unheard for 2 s is reported silent.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from typing import Any

from aeroexec.beliefs import BeliefMemory, BeliefUpdater, Struct, parse_belief
from aeroexec.fleet.node import SILENT_AFTER, FleetNode
from aeroexec.fleet.payloads import PayloadError, check_name, vector

logger = logging.getLogger(__name__)

SOCIAL = "SOCIAL_COMMUNICATION"
PERSISTENCE = 5.0  # wall seconds a belief heard from another drone lasts unless said again
BELIEFS_PERIOD = 1.0  # engine seconds between two snapshots of the shared beliefs
CHECK_PERIOD = 0.2  # wall seconds between two looks for silent drones and expired beliefs
MAX_BELIEFS = 500  # per snapshot


def _named(value: Any, sender: str) -> Any:
    """A term with the atom ``self`` replaced by ``sender``."""
    if value == "self":
        return sender
    if isinstance(value, tuple):
        return tuple(_named(v, sender) for v in value)
    if isinstance(value, Struct):
        return Struct(value.name, tuple(_named(v, sender) for v in value.args))
    return value


class FleetLink(BeliefUpdater):
    """Drone ``name``'s engine on the fleet ``node``; join it with :meth:`join`."""

    def __init__(self, node: FleetNode, name: str, engine: Any, share: tuple[str, ...] = (),
                 telemetry_rate: float = 5.0, persistence: float = PERSISTENCE) -> None:
        super().__init__(f"fleet link of {name}", period=0.0)
        self.node, self.name, self.engine = node, check_name(name, "the drone name"), engine
        self.share = tuple(share)
        self.telemetry_period = 1.0 / telemetry_rate
        self.persistence = persistence
        self.mission = ""
        self.state = "running"
        self._inbox: deque[tuple[str, str, dict[str, Any]]] = deque()
        self._positions: dict[str, dict[str, Any]] = {}  # newest telemetry per drone, not yet applied
        self._lock = threading.Lock()
        self._heard: dict[Struct, tuple[str, float]] = {}  # belief -> (sender, time.monotonic() last said)
        self._messages: dict[Struct, tuple[str, float]] = {}  # message(dN, Text) -> (sender, when received)
        self._where: dict[str, tuple[Struct, float]] = {}  # drone -> (its position belief, when received)
        self._next_check = 0.0
        self._events: list[dict[str, Any]] = []
        self._silent: set[str] = set()
        self._known: set[str] = set()
        self._next_telemetry = 0.0
        self._next_beliefs = 0.0
        self._last_shared: list[str] | None = None
        self._social: bool | None = None

    # -- wiring --------------------------------------------------------------------------------
    def join(self) -> FleetLink:
        """Attach to the node, become the engine's belief updater, message bus and event publisher."""
        self.node.attach(self)
        self.engine.updaters.append(self)
        self.engine.context.bus = self
        self.engine.log.subscribe(self._publish_event)
        return self

    def leave(self) -> None:
        self.node.detach(self.name)

    def submit(self, command: str, argument: str) -> Any:
        return self.engine.supervisor.submit(command, argument, origin="fleet")

    # -- Zenoh's thread ------------------------------------------------------------------------
    def post(self, sender: str, topic: str, message: dict[str, Any]) -> None:
        with self._lock:
            if topic == "telemetry":
                self._positions[sender] = message  # only the newest matters
            elif topic in ("beliefs", "broadcast"):
                self._inbox.append((sender, topic, message))

    # -- the message bus BROADCAST_MESSAGE uses ------------------------------------------------
    def name_of(self, memory: BeliefMemory) -> str | None:
        return self.name if memory is self.engine.memory else None

    def join_anonymous(self, memory: BeliefMemory, log: Any = None) -> str:
        return self.name

    def broadcast(self, sender: str, text: str) -> list[str]:
        """Send ``text`` to every drone of the fleet (and the operator); returns the drones heard lately."""
        self.node.publish(self.name, "broadcast", text=str(text))
        heard = self.node.heard()
        now = time.monotonic()
        return sorted(d for d, t in heard.items() if d != self.name and now - t < SILENT_AFTER)

    # -- the engine's thread -------------------------------------------------------------------
    def update(self, memory: BeliefMemory, now: float) -> None:
        if self._social is None:
            self._social = self._start_social()
        with self._lock:
            positions, self._positions = self._positions, {}
            inbox = list(self._inbox)
            self._inbox.clear()
        wall = time.monotonic()
        for sender, message in positions.items():
            self._place(sender, message, wall)
        for sender, topic, message in inbox:
            self._apply(self._message_beliefs if topic == "broadcast" else self._shared_beliefs,
                        sender, message, wall)
        if wall >= self._next_check:
            self._next_check = wall + CHECK_PERIOD
            self._check_silence(wall)
            self._expire(wall)
        self._publish_events()
        if now >= self._next_telemetry:
            self._next_telemetry = now + self.telemetry_period
            self._publish_telemetry(now)
        if self.share and now >= self._next_beliefs:
            self._next_beliefs = now + BELIEFS_PERIOD
            self._publish_beliefs()

    def _start_social(self) -> bool:
        if SOCIAL not in self.engine.catalog.capabilities:
            self.engine.log.record("fleet_link", detail=f"the catalog has no {SOCIAL} capability: this drone "
                                                        f"does not receive the fleet's messages")
            return False
        try:
            self.engine.resources.acquire("fleet link", [SOCIAL])
        except Exception as error:
            self.engine.log.record("fleet_link", detail=f"{SOCIAL} cannot run: {error}")
            return False
        self.engine.log.record("fleet_link", detail=f"{self.name} joined fleet {self.node.fleet}")
        return True

    def _apply(self, beliefs_of: Any, sender: str, message: dict[str, Any], wall: float) -> None:
        try:
            beliefs = beliefs_of(sender, message)
        except (PayloadError, ValueError, TypeError) as error:
            self.node.dropped += 1
            logger.warning("fleet %s: %s dropped a message from %s: %s", self.node.fleet, self.name, sender, error)
            return
        if sender not in self._known:
            self._known.add(sender)
            self.engine.log.record("fleet_drone_heard", detail=f"{sender} is in the fleet", drone=sender)
        for belief, announce in beliefs:
            try:
                added = self.engine.memory.add(belief)
            except ValueError as error:  # a predicate this drone does not know, a wrong arity...
                self.node.dropped += 1
                logger.warning("fleet %s: %s dropped %s from %s: %s", self.node.fleet, self.name, belief, sender,
                               error)
                continue
            if belief.name == "message":  # said once: it lasts while its sender is heard
                if added:
                    self._messages[belief] = (sender, wall)
            elif added or belief in self._heard:
                self._heard[belief] = (sender, wall)
            if added and announce:
                self.engine.log.record("fleet_belief", detail=f"from {sender}: {belief}", sender=sender,
                                       belief=str(belief))

    def _place(self, sender: str, message: dict[str, Any], wall: float) -> None:
        """``position(sender, (x, y, z))`` from its telemetry (replacing the last one)."""
        try:
            belief = Struct("position", (sender, vector(message.get("position"))))
        except PayloadError as error:
            self.node.dropped += 1
            logger.warning("fleet %s: %s dropped telemetry from %s: %s", self.node.fleet, self.name, sender, error)
            return
        if sender not in self._known:
            self._known.add(sender)
            self.engine.log.record("fleet_drone_heard", detail=f"{sender} is in the fleet", drone=sender)
        self.engine.memory.add(belief)
        self._where[sender] = (belief, wall)

    def _shared_beliefs(self, sender: str, message: dict[str, Any]) -> list[tuple[Struct, bool]]:
        texts = message.get("beliefs")
        if not isinstance(texts, list) or len(texts) > MAX_BELIEFS or not all(isinstance(t, str) for t in texts):
            raise PayloadError("beliefs must be a list of belief texts")
        out = []
        for text in texts:
            belief = _named(parse_belief(text), sender)
            out.append((belief, True))
        return out

    def _message_beliefs(self, sender: str, message: dict[str, Any]) -> list[tuple[Struct, bool]]:
        text = message.get("text")
        if not isinstance(text, str):
            raise PayloadError("a broadcast's text must be text")
        if not self._social or SOCIAL not in self.engine.resources.running():
            return []
        self.engine.log.record("message_received", detail=f"from {sender}: {text}", sender=sender, text=text,
                               receiver=self.name)
        return [(Struct("message", (sender, text)), False)]

    def _check_silence(self, wall: float) -> None:
        for drone, heard in self.node.heard().items():
            if drone == self.name:
                continue
            if wall - heard >= SILENT_AFTER and drone not in self._silent:
                self._silent.add(drone)
                self.engine.log.record("fleet_drone_silent", detail=f"{drone}: nothing heard for "
                                                                    f"{wall - heard:.1f} s", drone=drone)
            elif wall - heard < SILENT_AFTER and drone in self._silent:
                self._silent.discard(drone)
                self.engine.log.record("fleet_drone_heard", detail=f"{drone} is heard again", drone=drone)

    def _expire(self, wall: float) -> None:
        for belief, (_sender, said) in list(self._heard.items()):
            if wall - said >= self.persistence:
                del self._heard[belief]
                self.engine.memory.remove(belief)
        for sender, (belief, said) in list(self._where.items()):
            if wall - said >= self.persistence:
                del self._where[sender]
                self.engine.memory.remove(belief)
        if self._messages:
            heard = self.node.heard()
            for belief, (sender, received) in list(self._messages.items()):
                if wall - max(heard.get(sender, received), received) >= self.persistence:
                    del self._messages[belief]
                    self.engine.memory.remove(belief)

    @property
    def silent(self) -> set[str]:
        return set(self._silent)

    # -- publishing ----------------------------------------------------------------------------
    def _publish_telemetry(self, now: float) -> None:
        t = self.engine.drone.telemetry()
        active = sorted(self.engine.coordinator.active())
        self.node.publish(self.name, "telemetry", sent=time.time(), time=round(now, 3),
                          position=[round(v, 3) for v in t.position], velocity=[round(v, 3) for v in t.velocity],
                          yaw=round(t.yaw, 2), battery=round(t.battery_percent, 1),
                          state=str(getattr(t.landed_state, "value", t.landed_state)), mission=self.mission,
                          status=self.state, active=active)

    def _publish_beliefs(self) -> None:
        heard = set(self._heard) | set(self._messages) | {belief for belief, _ in self._where.values()}
        shared = []
        for predicate in self.share:
            for belief in self.engine.memory.beliefs(predicate):
                if belief not in heard:  # only what this drone knows itself, never what others told it
                    shared.append(str(belief))
        self.node.publish(self.name, "beliefs", beliefs=shared[:MAX_BELIEFS])

    def _publish_event(self, event: Any) -> None:
        """Keep an event for the next batch (one message per tick carries all of them)."""
        if event.kind in ("fleet_belief", "node_status"):
            return
        with self._lock:
            self._events.append({"time": round(event.time, 3), "kind": event.kind, "behavior": event.behavior,
                                 "detail": event.detail})

    def _publish_events(self) -> None:
        with self._lock:
            events, self._events = self._events, []
        if events:
            self.node.publish(self.name, "events", events=events)
