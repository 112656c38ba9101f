"""One drone's fleet link: what its engine tells the fleet and what it hears of the others, on its own tick.

Published (on the engine's thread): telemetry at ``telemetry_rate`` Hz of engine time (position, velocity, yaw,
battery, flight state, mission, active behaviors; also the drone's heartbeat), the engine's events (those of
a tick together, in one message), and the beliefs of the ``share`` predicates (``self`` as written) once a second
and when they change.

Heard (queued by the :class:`~aeroexec.fleet.node.FleetNode`, applied here): ``position(dN, (x, y, z))`` from
telemetry; BROADCAST_MESSAGE as ``message(dN, Text)`` while this drone's SOCIAL_COMMUNICATION capability runs;
and shared beliefs, with ``self`` replaced by the sender, accepted only when

- their predicate is one the sender shares (the roster's share list for it, else this drone's own ``share``),
- they are not about this drone: they do not name it, and are not of the predicates of its own state
  (``charge``, ``position``, ``flight_state``...) unless about the sender itself, and are not ``said``;
- they name no other member of the fleet (each drone speaks for itself).

Each accepted belief keeps its source: ``said(dN, Belief)`` holds while the sender keeps saying it, beside the
belief itself; a claim that contradicts a belief this drone formed itself (an exclusive predicate's other value)
is held only as ``said(dN, Belief)``. What a drone heard from another expires ``persistence`` seconds (wall time)
after it was last said (a message: after its sender was last heard); a drone unheard for 2 s is reported silent.
A refusal is counted by the node; the first of each sender and reason is an event (``fleet_refused``).
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from typing import Any

from aeroexec.beliefs import BeliefError, BeliefMemory, BeliefUpdater, ListTerm, Struct, Var, parse_belief
from aeroexec.engine.execution.updaters import TELEMETRY_PREDICATES
from aeroexec.fleet.node import SILENT_AFTER, FleetNode
from aeroexec.fleet.payloads import PayloadError, check_name, vector

logger = logging.getLogger(__name__)

SOCIAL = "SOCIAL_COMMUNICATION"
SAID = "said"
PERSISTENCE = 5.0  # wall seconds a belief heard from another drone lasts unless said again
BELIEFS_PERIOD = 1.0  # engine seconds between two snapshots of the shared beliefs
CHECK_PERIOD = 0.2  # wall seconds between two looks for silent drones and expired beliefs
MAX_BELIEFS = 500  # per snapshot
MAX_QUEUED_MESSAGES = 16  # broadcasts of one sender waiting for the next tick
MAX_MESSAGES = 100  # message(dN, Text) beliefs held per sender
OWN_STATE = frozenset(TELEMETRY_PREDICATES) | {"localization", "carry"}  # what a drone knows of itself


def _named(value: Any, sender: str) -> Any:
    """A term with the atom ``self`` replaced by ``sender``."""
    if value == "self":
        return sender
    if isinstance(value, tuple):
        return type(value)(_named(v, sender) for v in value) if isinstance(value, ListTerm) else tuple(
            _named(v, sender) for v in value)
    if isinstance(value, Struct):
        return Struct(value.name, tuple(_named(v, sender) for v in value.args))
    return value


def _atoms(value: Any, found: set[str] | None = None) -> set[str]:
    """Every atom (and string) of a term."""
    found = set() if found is None else found
    if isinstance(value, str):
        found.add(value)
    elif isinstance(value, tuple):
        for v in value:
            _atoms(v, found)
    elif isinstance(value, Struct):
        for v in value.args:
            _atoms(v, found)
    return found


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
        self._lock = threading.Lock()
        self._positions: dict[str, dict[str, Any]] = {}  # newest telemetry per drone, not yet applied
        self._snapshots: dict[str, dict[str, Any]] = {}  # newest shared beliefs per drone, not yet applied
        self._broadcasts: dict[str, deque[dict[str, Any]]] = {}  # broadcasts per drone, not yet applied
        self._refusals: list[tuple[str, str, str]] = []  # the node's new refusals, for the event log
        self._refused: set[tuple[str, str]] = set()  # (sender, reason) already in the event log
        self._heard: dict[Struct, tuple[str, float]] = {}  # belief -> (sender, time.monotonic() last said)
        self._messages: dict[Struct, tuple[str, float]] = {}  # message(dN, Text) -> (sender, when received)
        self._where: dict[str, tuple[Struct, float]] = {}  # drone -> (its position belief, when received)
        self._next_check = 0.0
        self._events: list[dict[str, Any]] = []
        self._silent: set[str] = set()
        self._known: set[str] = set()
        self._next_telemetry = 0.0
        self._next_beliefs = 0.0
        self._social: bool | None = None

    # -- wiring --------------------------------------------------------------------------------
    def join(self) -> FleetLink:
        """Attach to the node, become the engine's belief updater, message bus and event publisher."""
        memory = self.engine.memory
        if not memory.accepts(SAID):
            memory.declare(SAID, 2, multivalued=True)
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
        overflow = False
        with self._lock:
            if topic == "telemetry":
                self._positions[sender] = message  # only the newest matters
            elif topic == "beliefs":
                self._snapshots[sender] = message  # a snapshot: the newest says all
            elif topic == "broadcast":
                waiting = self._broadcasts.setdefault(sender, deque())
                overflow = len(waiting) >= MAX_QUEUED_MESSAGES
                if not overflow:
                    waiting.append(message)
        if overflow:
            reason = f"more than {MAX_QUEUED_MESSAGES} broadcasts in one tick"
            self.node.refuse(sender, reason, everyone=False)
            self.refused(sender, reason, "")

    def refused(self, sender: str, reason: str, example: str) -> None:
        """The node refused a message of ``sender`` for a new ``reason``: an event on this drone's next tick."""
        with self._lock:
            self._refusals.append((sender, reason, example))

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
            snapshots, self._snapshots = self._snapshots, {}
            broadcasts = [(s, m) for s, waiting in self._broadcasts.items() for m in waiting]
            self._broadcasts.clear()
            refusals, self._refusals = self._refusals, []
        for sender, reason, example in refusals:
            self._note_refusal(sender, reason, example)
        wall = time.monotonic()
        for sender, message in positions.items():
            self._place(sender, message, wall)
        for sender, message in snapshots.items():
            self._hear_beliefs(sender, message, wall)
        for sender, message in broadcasts:
            self._hear_broadcast(sender, message, wall)
        if wall >= self._next_check:
            self._next_check = wall + CHECK_PERIOD
            self._check_silence(wall)
            self._expire(wall)
            self.node.refusals.flush()
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

    def _refuse(self, sender: str, reason: str, example: str, what: str = "belief") -> None:
        """Count a refusal with the node; the first of its sender and reason is an event here."""
        self.node.refuse(sender, reason, example, what, everyone=False)
        self._note_refusal(sender, reason, example)

    def _note_refusal(self, sender: str, reason: str, example: str) -> None:
        if (sender, reason) not in self._refused:
            self._refused.add((sender, reason))
            self.engine.log.record("fleet_refused", detail=f"from {sender}: {reason}" + (f" ({example})" if example
                                                                                          else ""),
                                   sender=sender, reason=reason)

    def _heard_from(self, sender: str) -> None:
        if sender not in self._known:
            self._known.add(sender)
            self.engine.log.record("fleet_drone_heard", detail=f"{sender} is in the fleet", drone=sender)

    def _place(self, sender: str, message: dict[str, Any], wall: float) -> None:
        """``position(sender, (x, y, z))`` from its telemetry (replacing the last one)."""
        try:
            belief = Struct("position", (sender, vector(message.get("position"))))
        except PayloadError as error:
            self._refuse(sender, f"telemetry: {error.reason}", str(error), "message")
            return
        self._heard_from(sender)
        self.engine.memory.add(belief)
        self._where[sender] = (belief, wall)

    def _hear_beliefs(self, sender: str, message: dict[str, Any], wall: float) -> None:
        texts = message.get("beliefs")
        if not isinstance(texts, list) or len(texts) > MAX_BELIEFS or not all(isinstance(t, str) for t in texts):
            self._refuse(sender, f"not a list of at most {MAX_BELIEFS} belief texts", "", "message")
            return
        roster = self.node.roster
        shared = roster.shared_by(sender) if roster is not None and sender in roster.drones else self.share
        for text in texts:
            try:
                belief = _named(parse_belief(text), sender)
            except BeliefError as error:
                self._refuse(sender, "not a belief", f"{text}: {error}")
                continue
            reason = self._refusal_of(sender, belief, shared)
            if reason:
                self._refuse(sender, reason, str(belief))
                continue
            self._hold(sender, belief, wall)

    def _refusal_of(self, sender: str, belief: Struct, shared: tuple[str, ...]) -> str:
        """Why ``sender`` may not tell this drone ``belief`` ("" when it may)."""
        if belief.name == SAID:
            return "reports what others said (only a drone's own claims are heard)"
        if belief.name not in shared:
            return "a predicate the sender does not share"
        atoms = _atoms(belief)
        if self.name in atoms:
            return "about this drone"
        if belief.name in OWN_STATE and (not belief.args or belief.args[0] != sender):
            return "about this drone's own state"
        roster = self.node.roster
        members = roster.drones if roster is not None else self._known
        if any(atom in members and atom != sender for atom in atoms):
            return "about another member (each drone speaks for itself)"
        return ""

    def _hold(self, sender: str, belief: Struct, wall: float) -> None:
        """Believe ``belief`` as said by ``sender``: ``said(sender, belief)``, and the belief itself unless it
        contradicts one this drone formed itself."""
        memory = self.engine.memory
        said = Struct(SAID, (sender, belief))
        try:
            own = self._own_value(belief)
            memory.add(said)
            added = not own and memory.add(belief)
        except (BeliefError, ValueError, TypeError) as error:  # a predicate this drone does not know, an arity...
            self._refuse(sender, "a belief this drone cannot hold", f"{belief}: {error}")
            return
        self._heard_from(sender)
        self._heard[said] = (sender, wall)
        if own:
            self._refuse(sender, "contradicts what this drone believes itself (kept as said)", f"{belief} vs {own}")
            return
        if added or belief in self._heard:
            self._heard[belief] = (sender, wall)
        if added:
            self.engine.log.record("fleet_belief", detail=f"from {sender}: {belief}", sender=sender,
                                   belief=str(belief))

    def _own_value(self, belief: Struct) -> Struct | None:
        """The belief of this drone's own that ``belief`` would replace (another value of an exclusive predicate)."""
        declared = self.engine.catalog.predicates.get(belief.name)
        if belief.arity < 2 or declared is not None and declared.multivalued:
            return None
        for held in self.engine.memory.matching(Struct(belief.name, (*belief.args[:-1], Var("?")))):
            if held != belief and held not in self._heard:
                return held
        return None

    def _hear_broadcast(self, sender: str, message: dict[str, Any], wall: float) -> None:
        text = message.get("text")
        if not isinstance(text, str):
            self._refuse(sender, "a broadcast whose text is not text", "", "message")
            return
        self._heard_from(sender)
        if not self._social or SOCIAL not in self.engine.resources.running():
            return
        if sum(1 for s, _ in self._messages.values() if s == sender) >= MAX_MESSAGES:
            self._refuse(sender, f"more than {MAX_MESSAGES} messages held at once", text, "message")
            return
        self.engine.log.record("message_received", detail=f"from {sender}: {text}", sender=sender, text=text,
                               receiver=self.name)
        belief = Struct("message", (sender, text))
        if self.engine.memory.add(belief):
            self._messages[belief] = (sender, wall)

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
            if predicate == SAID:
                continue
            for belief in self.engine.memory.beliefs(predicate):
                if belief not in heard:  # only what this drone knows itself, never what others told it
                    shared.append(str(belief))
        self.node.publish(self.name, "beliefs", beliefs=shared[:MAX_BELIEFS])

    def _publish_event(self, event: Any) -> None:
        """Keep an event for the next batch (one message per tick carries all of them)."""
        if event.kind in ("fleet_belief", "node_status", "fleet_refused"):
            return
        with self._lock:
            self._events.append({"time": round(event.time, 3), "kind": event.kind, "behavior": event.behavior,
                                 "detail": event.detail})

    def _publish_events(self) -> None:
        with self._lock:
            events, self._events = self._events, []
        if events:
            self.node.publish(self.name, "events", events=events)
