"""One drone's fleet link: what its engine tells the fleet and what it hears of the others, on its own tick.

Said (on the engine's thread, kept by the :class:`~aeroexec.fleet.node.FleetNode` for the end of the period):
telemetry at ``telemetry_rate`` Hz of engine time (position, velocity, yaw, battery, flight state, mission,
active behaviors; also the drone's heartbeat), the engine's events of the period, and the beliefs of the
``share`` predicates (``self`` as written) once a second and when they change.

Heard (what the process's table took at the end of the last period, :mod:`aeroexec.fleet.table`):
``position(dN, (x, y, z))`` and ``velocity(dN, (vx, vy, vz))`` (to 0.1 m/s) of every other drone, answered by this
drone's belief memory from the process's one table (:mod:`aeroexec.beliefs.shared`: never written here, so hearing
N drones costs this drone nothing; a mate's position coming or going is told to the memory's listeners, so rules
and safety monitors that read it look again);
BROADCAST_MESSAGE as ``message(dN, Text)`` while this drone's SOCIAL_COMMUNICATION capability runs; and shared
beliefs, with ``self`` replaced by the sender, accepted only when

- their predicate is one the sender shares (the roster's share list for it, else this drone's own ``share``),
- they are not about this drone: they do not name it, and are not of the predicates of its own state
  (``charge``, ``position``, ``flight_state``...) unless about the sender itself, and are not ``said``;
- they name no other member of the fleet (each drone speaks for itself).

Each accepted belief keeps its source: ``said(dN, Belief)`` holds while the sender keeps saying it, beside the
belief itself; a claim that contradicts a belief this drone formed itself (an exclusive predicate's other value)
is held only as ``said(dN, Belief)``. A belief of a predicate the fleet file's ``trust:`` names (``trust: {code:
2}``) is believed only while that many distinct members say it; until then only its ``said`` beliefs are held (a
``fleet_claim`` event), so one compromised member cannot make the drone believe it alone. What a drone heard from
another expires the table's ``persistence`` (5 s) after it was last said (a message: after its sender was last
heard); a drone unheard for 2 s is reported silent (engine time for the drones of this process, wall time for those
of other processes: :mod:`aeroexec.fleet.table`). A refusal is counted by the node; the first of each sender and
reason is an event (``fleet_refused``).
"""

from __future__ import annotations

import logging
import threading
from typing import Any

from aeroexec.beliefs import BeliefError, BeliefMemory, BeliefUpdater, EvaluationRefused, Struct, Var
from aeroexec.engine.execution.updaters import TELEMETRY_PREDICATES
from aeroexec.fleet.node import FleetNode
from aeroexec.fleet.payloads import check_name
from aeroexec.fleet.table import MAX_BELIEFS, News, Said

logger = logging.getLogger(__name__)

SOCIAL = "SOCIAL_COMMUNICATION"
SAID = "said"
VELOCITY = "velocity"  # a mate's, from its telemetry
BELIEFS_PERIOD = 1.0  # engine seconds between two snapshots of the shared beliefs
CHECK_PERIOD = 0.2  # engine seconds between two looks for expired messages
MAX_QUEUED_MESSAGES = 16  # broadcasts of one sender taken in one period
MAX_MESSAGES = 100  # message(dN, Text) beliefs held per sender
OWN_STATE = frozenset(TELEMETRY_PREDICATES) | {"localization", "carry", VELOCITY}  # what a drone knows of itself
QUIET = frozenset({"fleet_belief", "fleet_claim", "node_status", "fleet_refused", "fleet_drone_heard",
                   "fleet_drone_silent"})
NAMED = 3  # drones named in one fleet_drone_heard line


class FleetLink(BeliefUpdater):
    """Drone ``name``'s engine on the fleet ``node``; join it with :meth:`join`."""

    def __init__(self, node: FleetNode, name: str, engine: Any, share: tuple[str, ...] = (),
                 telemetry_rate: float = 5.0, trust: dict[str, int] | None = None) -> None:
        super().__init__(f"fleet link of {name}", period=0.0)
        self.node, self.name, self.engine = node, check_name(name, "the drone name"), engine
        self.share = tuple(share)
        self.trust = dict(trust or {})  # without a roster (a drone in its own process): its own --trust
        self.telemetry_period = 1.0 / telemetry_rate
        self.mission = ""
        self.state = "running"
        self._lock = threading.Lock()
        self._news: list[News] = []  # what the table took, not yet applied
        self._refusals: list[tuple[str, str, str]] = []  # the node's new refusals, for the event log
        self._refused: set[tuple[str, str]] = set()  # (sender, reason) already in the event log
        self._heard: dict[Struct, set[str]] = {}  # a belief held because others say it -> who says it
        self._claims: dict[Struct, set[str]] = {}  # a belief of a trust: predicate -> the members saying it
        self._messages: dict[Struct, str] = {}  # message(dN, Text) -> its sender
        self._next_check = 0.0
        self._events: list[dict[str, Any]] = []
        self._silent: set[str] = set()
        self._known: set[str] = set()  # drones heard of before their telemetry came (their beliefs, broadcasts)
        self._next_telemetry = 0.0
        self._next_beliefs = 0.0
        self._social: bool | None = None

    # -- wiring --------------------------------------------------------------------------------
    def join(self) -> FleetLink:
        """Attach to the node, answer other drones' positions from its table, become the engine's belief updater,
        message bus and event publisher."""
        memory = self.engine.memory
        if not memory.accepts(SAID):
            memory.declare(SAID, 2, multivalued=True)
        if not memory.accepts(VELOCITY):
            memory.declare(VELOCITY, 2)
        hidden = ((self.name,),)
        memory.share(self.node.table.positions.view(hidden=hidden))
        memory.share(self.node.table.velocities.view(hidden=hidden))
        self.node.attach(self)
        self.engine.updaters.append(self)
        self.engine.context.bus = self
        self.engine.log.subscribe(self._publish_event)
        return self

    def leave(self) -> None:
        self.node.detach(self.name)

    def submit(self, command: str, argument: str) -> Any:
        return self.engine.supervisor.submit(command, argument, origin="fleet")

    # -- the node ------------------------------------------------------------------------------
    def hear(self, news: News) -> None:
        """What the process's table took at the end of a period (applied on this drone's next tick; news of nothing
        changes nothing)."""
        if news:
            self._news.append(news)

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
        self.node.say(self.name, "broadcast", text=str(text))
        now, table = self.engine.now(), self.node.table
        lately = [d for d in table.reported if table.since(table.reported, d, now) < table.silent_after]
        return sorted(d for d in lately if d != self.name)

    # -- the engine's thread -------------------------------------------------------------------
    def update(self, memory: BeliefMemory, now: float) -> None:
        if self._social is None:
            self._social = self._start_social()
        if self._refusals:  # the lock only when there is something to take (a refusal added meanwhile: next period)
            with self._lock:
                refusals, self._refusals = self._refusals, []
            for sender, reason, example in refusals:
                self._note_refusal(sender, reason, example)
        if self._news:  # a new list only when there is news (most periods have none)
            news, self._news = self._news, []
            for taken in news:
                self._take(taken)
        if self._messages and now >= self._next_check:
            self._next_check = now + CHECK_PERIOD
            self._expire(now)
        if self._events:
            self._publish_events()
        if now >= self._next_telemetry:
            self._next_telemetry = now + self.telemetry_period
            self._publish_telemetry(now)
        if self.share and now >= self._next_beliefs:
            self._next_beliefs = now + BELIEFS_PERIOD
            self._publish_beliefs()
        if not self.node.driven:  # alone in its process: this drone's period ends here
            self.node.exchange(now)

    def tell(self, state: str) -> None:
        """Say how this drone's mission ended (its telemetry's status), at once."""
        self.state = state
        now = self.engine.now()
        self._publish_events()
        self._publish_telemetry(now)
        if not self.node.driven:
            self.node.exchange(now)

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

    def _take(self, news: News) -> None:
        log = self.engine.log
        heard = [d for d in news.heard if d != self.name]
        if heard:
            named = ", ".join(heard[:NAMED]) + (f" and {len(heard) - NAMED} more" if len(heard) > NAMED else "")
            log.record("fleet_drone_heard", detail=f"{named} {'is' if len(heard) == 1 else 'are'} in the fleet",
                       drones=heard)
        memory = self.engine.memory
        for drone, where in news.came:
            if drone != self.name:
                memory.announce("added", Struct("position", (drone, where)))
        for drone, where in news.went:
            if drone != self.name:
                memory.announce("removed", Struct("position", (drone, where)))
        for drone, unheard in news.silent:
            if drone != self.name and drone not in self._silent:
                self._silent.add(drone)
                log.record("fleet_drone_silent", detail=f"{drone}: nothing heard for {unheard:.1f} s", drone=drone)
        for drone in news.again:
            if drone in self._silent:
                self._silent.discard(drone)
                log.record("fleet_drone_heard", detail=f"{drone} is heard again", drones=[drone])
        for sender, belief in news.unsaid:
            if sender != self.name:
                self._forget(sender, belief)
        for sender, said in news.said:
            if sender != self.name:
                reason = self._refusal_of(sender, said)
                if reason:
                    self._refuse(sender, reason, str(said.belief))
                else:
                    self._hold(sender, said.belief)
        received: dict[str, int] = {}
        for sender, text in news.broadcasts:
            if sender != self.name:
                received[sender] = received.get(sender, 0) + 1
                if received[sender] > MAX_QUEUED_MESSAGES:
                    if received[sender] == MAX_QUEUED_MESSAGES + 1:
                        self._refuse(sender, f"more than {MAX_QUEUED_MESSAGES} broadcasts in one tick", "",
                                     "message")
                    continue
                self._hear_broadcast(sender, text)

    def _heard_from(self, sender: str) -> None:
        """A drone whose telemetry never came is heard when this drone first takes something it said."""
        if sender not in self.node.table.reported and sender not in self._known:
            self._known.add(sender)
            self.engine.log.record("fleet_drone_heard", detail=f"{sender} is in the fleet", drones=[sender])

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

    def _refusal_of(self, sender: str, said: Said) -> str:
        """Why ``sender`` may not tell this drone ``said`` ("" when it may)."""
        belief = said.belief
        if belief.name == SAID:
            return "reports what others said (only a drone's own claims are heard)"
        roster = self.node.roster
        shared = roster.shared_by(sender) if roster is not None and sender in roster.drones else self.share
        if belief.name not in shared:
            return "a predicate the sender does not share"
        if self.name in said.atoms:
            return "about this drone"
        if belief.name in OWN_STATE and (not belief.args or belief.args[0] != sender):
            return "about this drone's own state"
        members = roster.drones if roster is not None else self.node.table.heard
        if any(atom in members and atom != sender for atom in said.atoms):
            return "about another member (each drone speaks for itself)"
        return ""

    def _needed(self, belief: Struct) -> int:
        """How many distinct members must say ``belief`` before this drone believes it (the fleet file's trust:, or
        this drone's own without a roster)."""
        roster = self.node.roster
        return roster.needed(belief.name) if roster is not None else self.trust.get(belief.name, 1)

    def _hold(self, sender: str, belief: Struct) -> None:
        """Believe ``belief`` as said by ``sender``: ``said(sender, belief)``, and the belief itself unless it
        contradicts one this drone formed itself or, for a predicate the fleet's ``trust:`` names, until enough
        distinct members say it."""
        memory = self.engine.memory
        said = Struct(SAID, (sender, belief))
        needed = self._needed(belief)
        claims = self._claims.setdefault(belief, set()) if needed > 1 else {sender}
        claims.add(sender)
        agreed = len(claims) >= needed
        try:
            own = self._own_value(belief)
            memory.add(said)
            added = not own and agreed and memory.add(belief)
        except (BeliefError, ValueError, TypeError) as error:  # a predicate this drone does not know, an arity...
            claims.discard(sender)
            self._refuse(sender, "a belief this drone cannot hold", f"{belief}: {error}")
            return
        self._heard_from(sender)
        self._heard.setdefault(said, set()).add(sender)
        if own:
            self._refuse(sender, "contradicts what this drone believes itself (kept as said)", f"{belief} vs {own}")
            return
        if not agreed:
            self.engine.log.record("fleet_claim", detail=f"from {sender}: {belief} (said by {len(claims)} of the "
                                                         f"{needed} members needed to believe it)",
                                   sender=sender, belief=str(belief), sources=sorted(claims), needed=needed)
            return
        if added or belief in self._heard:
            self._heard.setdefault(belief, set()).update(claims)
        if added:
            sources = ", ".join(sorted(claims))
            self.engine.log.record("fleet_belief", detail=f"from {sources}: {belief}", sender=sender,
                                   belief=str(belief), **({"sources": sorted(claims)} if needed > 1 else {}))

    def _forget(self, sender: str, belief: Struct) -> None:
        """``sender`` no longer says ``belief``: forget it unless enough other drones still do (one, or the
        fleet's ``trust:`` for its predicate)."""
        claims = self._claims.get(belief)
        if claims is not None:
            claims.discard(sender)
            if not claims:
                del self._claims[belief]
        needed = self._needed(belief)
        for held in (Struct(SAID, (sender, belief)), belief):
            sources = self._heard.get(held)
            if sources is not None and sender in sources:
                sources.discard(sender)
                if not sources or held is belief and len(sources) < needed:
                    del self._heard[held]
                    self.engine.memory.remove(held)

    def _own_value(self, belief: Struct) -> Struct | None:
        """The belief of this drone's own that ``belief`` would replace (another value of an exclusive predicate)."""
        declared = self.engine.catalog.predicates.get(belief.name)
        if belief.arity < 2 or declared is not None and declared.multivalued:
            return None
        for held in self.engine.memory.matching(Struct(belief.name, (*belief.args[:-1], Var("?")))):
            if held != belief and held not in self._heard:
                return held
        return None

    def _hear_broadcast(self, sender: str, text: str) -> None:
        self._heard_from(sender)
        if not self._social or SOCIAL not in self.engine.resources.running():
            return
        if sum(1 for s in self._messages.values() if s == sender) >= MAX_MESSAGES:
            self._refuse(sender, f"more than {MAX_MESSAGES} messages held at once", text, "message")
            return
        self.engine.log.record("message_received", detail=f"from {sender}: {text}", sender=sender, text=text,
                               receiver=self.name)
        belief = Struct("message", (sender, text))
        if self.engine.memory.add(belief):
            self._messages[belief] = sender

    def _expire(self, now: float) -> None:
        table = self.node.table
        for belief, sender in list(self._messages.items()):
            if table.since(table.heard, sender, now) >= table.persistence:
                del self._messages[belief]
                self.engine.memory.remove(belief)

    @property
    def silent(self) -> set[str]:
        return set(self._silent)

    # -- saying --------------------------------------------------------------------------------
    def _publish_telemetry(self, now: float) -> None:
        engine = self.engine
        t = engine.drone.telemetry()
        x, y, z = t.position
        vx, vy, vz = t.velocity
        self.node.say(self.name, "telemetry", time=round(now, 3), position=[round(x, 3), round(y, 3), round(z, 3)],
                      velocity=[round(vx, 3), round(vy, 3), round(vz, 3)], yaw=round(t.yaw, 2),
                      battery=round(t.battery_percent, 1), state=str(getattr(t.landed_state, "value", t.landed_state)),
                      mission=self.mission, status=self.state, active=sorted(engine.coordinator.active()))

    def _publish_beliefs(self) -> None:
        shared = []
        for predicate in self.share:
            if predicate == SAID:
                continue
            try:
                known = list(self.engine.memory.beliefs(predicate))
            except EvaluationRefused as refused:  # rules past the bound of a step: shared again next period
                logger.warning("drone %s: the shared beliefs %s: %s", self.name, predicate, refused)
                continue
            for belief in known:
                if belief not in self._heard and belief not in self._messages:  # only what it knows itself
                    shared.append(str(belief))
        self.node.say(self.name, "beliefs", beliefs=shared[:MAX_BELIEFS])

    def _publish_event(self, event: Any) -> None:
        """Keep an event for the period's end (one message per period carries all of them)."""
        if event.kind in QUIET:
            return
        with self._lock:
            self._events.append({"time": round(event.time, 3), "kind": event.kind, "behavior": event.behavior,
                                 "detail": event.detail})

    def _publish_events(self) -> None:
        if not self._events:  # nothing to say this period (an event kept meanwhile goes with the next)
            return
        with self._lock:
            events, self._events = self._events, []
        if events:
            self.node.say(self.name, "events", events=events)
