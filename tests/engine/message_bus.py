"""A message bus between engines of one test process (the engine's ``bus``, as a fleet link is one in flight): what
one broadcasts, the others believe. Drones of a run exchange messages over their fleet link (``aeroexec.fleet``).

Each engine joins under a name with its belief memory (and event log); ``broadcast(sender, text)`` gives every
other member the belief ``message(Sender, Text)`` (multi-valued) and a ``message_received`` event.

Delivery is immediate by default (the receiver's memory is written in the sender's thread: right when every
engine ticks in one thread, as tests and lockstep runs do). Engines that run in their own threads join with
:meth:`MessageBus.join_engine`: their messages wait in a mailbox that the receiving engine empties on its own
tick, as one of its belief updaters.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from typing import Any

from aeroexec.beliefs import BeliefMemory, BeliefUpdater, Struct
from aeroexec.engine.events import EventLog

logger = logging.getLogger(__name__)


class Mailbox(BeliefUpdater):
    """One member of the bus: delivers the messages addressed to it into its memory."""

    def __init__(self, name: str, memory: BeliefMemory, log: EventLog | None = None, deferred: bool = False) -> None:
        super().__init__(f"mailbox of {name}", period=0.0)
        self.member = name
        self.memory = memory
        self.log = log
        self.deferred = deferred
        self.received: list[tuple[str, str]] = []
        self._queue: deque[tuple[str, str]] = deque()
        self._lock = threading.Lock()

    def post(self, sender: str, text: str) -> None:
        """A message for this member: delivered now, or on the member's next tick when deferred."""
        if self.deferred:
            with self._lock:
                self._queue.append((sender, text))
        else:
            self._deliver(sender, text)

    def update(self, memory: BeliefMemory, now: float) -> None:
        with self._lock:
            waiting = list(self._queue)
            self._queue.clear()
        for sender, text in waiting:
            self._deliver(sender, text)

    def _deliver(self, sender: str, text: str) -> None:
        self.received.append((sender, text))
        self.memory.add(Struct("message", (sender, text)))
        if self.log is not None:
            self.log.record("message_received", detail=f"from {sender}: {text}", sender=sender, text=text,
                            receiver=self.member)
        logger.debug("%s received from %s: %s", self.member, sender, text)


class MessageBus:
    """The drones of one run; thread-safe."""

    def __init__(self) -> None:
        self._members: dict[str, Mailbox] = {}
        self._lock = threading.RLock()
        self.history: list[tuple[str, str, tuple[str, ...]]] = []  # (sender, text, receivers)

    def join(self, name: str, memory: BeliefMemory, log: EventLog | None = None, *,
             deferred: bool = False) -> Mailbox:
        """Make ``name`` (with this memory) a member; joining again with the same memory returns its mailbox."""
        name = str(name)
        if not name or name == "self":
            raise ValueError(f"a drone cannot join the message bus as {name!r}")
        with self._lock:
            known = self._members.get(name)
            if known is not None:
                if known.memory is not memory:
                    raise ValueError(f"another drone has joined the message bus as {name}")
                return known
            mailbox = Mailbox(name, memory, log, deferred)
            self._members[name] = mailbox
            return mailbox

    def join_engine(self, name: str, engine: Any) -> Mailbox:
        """Join an engine (its memory and log) so that its messages are delivered on its own tick."""
        mailbox = self.join(name, engine.memory, engine.log, deferred=True)
        if mailbox not in engine.updaters:
            engine.updaters.append(mailbox)
        if engine.context.bus is None:
            engine.context.bus = self
        return mailbox

    def join_anonymous(self, memory: BeliefMemory, log: EventLog | None = None) -> str:
        """Join under the first free name ``drone_N`` (a drone that broadcasts without having joined)."""
        with self._lock:
            known = self.name_of(memory)
            if known is not None:
                return known
            number = 1
            while f"drone_{number}" in self._members:
                number += 1
            self.join(f"drone_{number}", memory, log)
            return f"drone_{number}"

    def leave(self, name: str) -> None:
        with self._lock:
            self._members.pop(name, None)

    def members(self) -> list[str]:
        with self._lock:
            return sorted(self._members)

    def name_of(self, memory: BeliefMemory) -> str | None:
        """The name under which the drone with this memory joined, or None."""
        with self._lock:
            return next((name for name, box in self._members.items() if box.memory is memory), None)

    def broadcast(self, sender: str, text: str) -> list[str]:
        """Deliver ``text`` from ``sender`` to every other member; returns their names."""
        with self._lock:
            receivers = [box for name, box in self._members.items() if name != sender]
            self.history.append((sender, text, tuple(box.member for box in receivers)))
            for box in receivers:
                try:
                    box.post(sender, text)
                except Exception:
                    logger.exception("the message from %s could not be delivered to %s", sender, box.member)
        return [box.member for box in receivers]
