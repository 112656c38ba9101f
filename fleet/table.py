"""What one process knows of its fleet's drones, held once however many drones it flies: the table its drones'
links read (:mod:`aeroexec.fleet.link`).

The process's node hands it what the fleet said in one engine period, at the period's end, in the same order in
every process (:meth:`FleetTable.take`); it returns what changed (:class:`News`), which each local link applies on
its next tick. Per message its work does not depend on the number of drones:

- telemetry: where the drone is and how it moves, one row of :attr:`FleetTable.positions` (``position(dN, (x, y,
  z))``) and of :attr:`FleetTable.velocities` (``velocity(dN, (vx, vy, vz))``, to 0.1 m/s), answered by every local
  drone's belief memory from these relations (:mod:`aeroexec.beliefs.shared`); a drone whose position row comes or
  goes is news (``came``, ``went``: what watches a memory's beliefs hears of a mate appearing or going);
- shared beliefs: parsed once, named after their sender; only what a sender says anew is news;
- broadcasts: passed on.

Time is the engine's for the drones of this process (on one simulated time): a drone unheard for
:data:`SILENT_AFTER` seconds is silent; its position, and what it said, expire :data:`PERSISTENCE` seconds after it
was last heard or said. A drone flown by another process (``aeroexec run --fleet``, another machine's fleet) keeps
its own time, so what it says is timed on the wall clock. One heap per clock holds every deadline, each drone (and
each belief said) in it once.
"""

from __future__ import annotations

import heapq
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from aeroexec.beliefs import BeliefError, ListTerm, Struct, parse_belief
from aeroexec.beliefs.shared import SharedBeliefs
from aeroexec.fleet.payloads import PayloadError, vector

PERSISTENCE = 5.0  # engine seconds a position or a belief heard from another drone lasts unless said again
SILENT_AFTER = 2.0  # engine seconds without telemetry after which a drone is silent
MAX_BELIEFS = 500  # per snapshot
_PARSED = 20_000  # belief texts remembered parsed

SILENCE, POSITION, BELIEF = 0, 1, 2  # what a deadline is for


@dataclass(frozen=True)
class Said:
    """A belief a drone said (``self`` replaced by its name), and every atom in it."""

    belief: Struct
    atoms: frozenset[str]


@dataclass
class News:
    """What changed when the fleet's messages of one period were taken, for every local link."""

    time: float
    heard: list[str] = field(default_factory=list)  # drones whose telemetry came for the first time
    came: list[tuple[str, tuple]] = field(default_factory=list)  # position rows that appeared: (drone, where)
    went: list[tuple[str, tuple]] = field(default_factory=list)  # position rows that expired: (drone, where)
    again: list[str] = field(default_factory=list)  # silent drones heard again
    silent: list[tuple[str, float]] = field(default_factory=list)  # drones silent now, and unheard for how long
    said: list[tuple[str, Said]] = field(default_factory=list)  # beliefs said anew
    unsaid: list[tuple[str, Struct]] = field(default_factory=list)  # beliefs no longer said (expired)
    broadcasts: list[tuple[str, str]] = field(default_factory=list)

    def __bool__(self) -> bool:
        return bool(self.heard or self.came or self.went or self.again or self.silent or self.said or self.unsaid
                    or self.broadcasts)


def named(value: Any, sender: str) -> Any:
    """A term with the atom ``self`` replaced by ``sender``."""
    if value == "self":
        return sender
    if isinstance(value, tuple):
        return type(value)(named(v, sender) for v in value) if isinstance(value, ListTerm) else tuple(
            named(v, sender) for v in value)
    if isinstance(value, Struct):
        return Struct(value.name, tuple(named(v, sender) for v in value.args))
    return value


def atoms(value: Any, found: set[str] | None = None) -> set[str]:
    """Every atom (and string) of a term."""
    found = set() if found is None else found
    if isinstance(value, str):
        found.add(value)
    elif isinstance(value, tuple):
        for v in value:
            atoms(v, found)
    elif isinstance(value, Struct):
        for v in value.args:
            atoms(v, found)
    return found


Refuse = Callable[[str, str, str, str], None]  # (sender, reason, example, what)


class FleetTable:
    """The fleet as this process hears it. ``refuse(sender, reason, example, what)`` counts a refused message."""

    def __init__(self, refuse: Refuse, persistence: float = PERSISTENCE, silent_after: float = SILENT_AFTER) -> None:
        self.refuse = refuse
        self.persistence, self.silent_after = persistence, silent_after
        self.positions = SharedBeliefs("position", 2)  # every drone heard, where it last said it was
        self.where: dict[str, tuple[float, float, float]] = {}  # the same, by drone
        self.velocities = SharedBeliefs("velocity", 2)  # every drone heard whose telemetry says how it moves
        self.telemetry: dict[str, dict[str, Any]] = {}  # each drone's newest telemetry
        # the times below are each drone's clock's: the engine's, or the wall's for a drone of the outside
        self.outside: set[str] = set()  # drones of processes of their own, not on this run's time
        self.heard: dict[str, float] = {}  # when each drone was last heard (any message)
        self.silent: set[str] = set()
        self.said: dict[str, dict[Struct, float]] = {}  # sender -> belief -> when it was last said
        self.reported: dict[str, float] = {}  # when each drone's newest telemetry came
        self._atoms: dict[Struct, frozenset[str]] = {}
        self._parsed: dict[str, Struct | BeliefError] = {}
        self._heaps: tuple[list, list] = ([], [])  # deadlines on the engine's clock, on the wall's
        self._due: set[tuple[int, str, Any]] = set()  # what has a deadline in a heap
        self._sequence = 0
        self._now = (0.0, 0.0)

    def since(self, times: dict[str, float], drone: str, now: float) -> float:
        """Seconds since ``times[drone]`` (:attr:`heard`, :attr:`reported`) by the drone's clock, ``now`` being the
        engine's time; infinite when never."""
        last = times.get(drone)
        if last is None:
            return float("inf")
        return (time.monotonic() if drone in self.outside else now) - last

    def take(self, messages: list[tuple[str, str, dict[str, Any]]], now: float,
             outside: frozenset[str] | set[str] = frozenset()) -> News:
        """Apply one period's messages ``(drone, topic, fields)`` (telemetry, beliefs, broadcasts; events are the
        views' business) at engine time ``now``, then the deadlines due; what changed. ``outside``: the drones of
        these messages that fly in processes of their own."""
        news = News(now)
        self.outside |= outside
        self._now = (now, time.monotonic())
        for drone, topic, fields in messages:
            if topic == "telemetry":
                self._telemetry(drone, fields, now, news)
            elif topic == "beliefs":
                self._beliefs(drone, fields, now, news)
            elif topic == "broadcast":
                text = fields.get("text")
                if not isinstance(text, str):
                    self.refuse(drone, "a broadcast whose text is not text", "", "message")
                    continue
                self._heard(drone, now)
                news.broadcasts.append((drone, text))
        for clock in (0, 1):
            self._deadlines(clock, news)
        return news

    def _clock(self, drone: str) -> int:
        return 1 if drone in self.outside else 0

    def _heard(self, drone: str, now: float) -> float:
        """Note ``drone`` heard; its clock's time now."""
        now = self._now[self._clock(drone)]
        self.heard[drone] = now
        return now

    def _telemetry(self, drone: str, fields: dict[str, Any], now: float, news: News) -> None:
        try:
            where = vector(fields.get("position"))
        except PayloadError as error:  # a heartbeat that says nothing: not heard
            self.refuse(drone, f"telemetry: {error.reason}", str(error), "message")
            return
        now = self._heard(drone, now)
        self.telemetry[drone] = fields
        if drone not in self.reported:
            news.heard.append(drone)
        self.reported[drone] = now
        if drone in self.silent:
            self.silent.discard(drone)
            news.again.append(drone)
        was = self.where.get(drone)
        if was != where:
            self.where[drone] = where
            self.positions.put((drone, where))
            if was is None:
                news.came.append((drone, where))
        try:
            vx, vy, vz = vector(fields.get("velocity"))
        except PayloadError:  # telemetry without a velocity: none known
            self.velocities.drop((drone,))
        else:
            self.velocities.put((drone, (round(vx, 1), round(vy, 1), round(vz, 1))))
        self._schedule(SILENCE, drone, None, now + self.silent_after)
        self._schedule(POSITION, drone, None, now + self.persistence)

    def _beliefs(self, sender: str, fields: dict[str, Any], now: float, news: News) -> None:
        texts = fields.get("beliefs")
        if not isinstance(texts, list) or len(texts) > MAX_BELIEFS or not all(isinstance(t, str) for t in texts):
            self.refuse(sender, f"not a list of at most {MAX_BELIEFS} belief texts", "", "message")
            return
        now = self._heard(sender, now)
        held = self.said.setdefault(sender, {})
        for text in texts:
            parsed = self._parse(text)
            if isinstance(parsed, BeliefError):
                self.refuse(sender, "not a belief", f"{text}: {parsed}", "belief")
                continue
            belief = named(parsed, sender)
            if belief not in held:
                found = self._atoms.get(belief)
                if found is None:
                    found = self._atoms[belief] = frozenset(atoms(belief))
                news.said.append((sender, Said(belief, found)))
                self._schedule(BELIEF, sender, belief, now + self.persistence)
            held[belief] = now

    def _parse(self, text: str) -> Struct | BeliefError:
        parsed = self._parsed.get(text)
        if parsed is None:
            try:
                parsed = parse_belief(text)
            except BeliefError as error:
                parsed = error
            if len(self._parsed) >= _PARSED:
                self._parsed.clear()
            self._parsed[text] = parsed
        return parsed

    def _schedule(self, kind: int, drone: str, belief: Any, due: float) -> None:
        """A deadline for ``kind`` of ``drone`` (and ``belief``), unless one is in the heap (then it is looked at
        again when it comes)."""
        if (kind, drone, belief) in self._due:
            return
        self._due.add((kind, drone, belief))
        self._sequence += 1
        heapq.heappush(self._heaps[self._clock(drone)], (due, self._sequence, kind, drone, belief))

    def _deadlines(self, clock: int, news: News) -> None:
        heap, now = self._heaps[clock], self._now[clock]
        while heap and heap[0][0] <= now:
            _, _, kind, drone, belief = heapq.heappop(heap)
            self._due.discard((kind, drone, belief))
            if kind == BELIEF:
                held = self.said.get(drone, {})
                last = held.get(belief)
                if last is None:
                    continue
                if last + self.persistence <= now:
                    del held[belief]
                    self._atoms.pop(belief, None)
                    news.unsaid.append((drone, belief))
                else:
                    self._schedule(kind, drone, belief, last + self.persistence)
                continue
            last = self.reported.get(drone)
            if last is None:
                continue
            if kind == SILENCE:
                if last + self.silent_after > now:
                    self._schedule(kind, drone, None, last + self.silent_after)
                elif drone not in self.silent:
                    self.silent.add(drone)
                    news.silent.append((drone, now - last))
            elif last + self.persistence > now:
                self._schedule(kind, drone, None, last + self.persistence)
            else:
                where = self.where.pop(drone, None)
                self.positions.drop((drone,))
                self.velocities.drop((drone,))
                if where is not None:
                    news.went.append((drone, where))


__all__ = ["MAX_BELIEFS", "PERSISTENCE", "SILENT_AFTER", "FleetTable", "News", "Said", "atoms", "named"]
