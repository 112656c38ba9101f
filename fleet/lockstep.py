"""A fleet spread over worker processes, in lockstep: one simulated time that the workers agree on.

Each worker ends every engine period with one ``step`` message on the key of its first drone: the period, how many
``tick`` messages its drones put in it, and whether every flight of the worker has ended. Before its drones tick
again, a worker takes every other worker's ticks of that period (:meth:`Lockstep.complete`), so what a drone hears,
and when, is what it would hear with every drone in one process: the same event logs per seed whichever worker
flies it and however loaded the machine is. A worker whose step does not come within ``patience`` wall seconds, or
that its coordinator says has left, is waited for no more: its drones fall silent in the fleet's table.

Before the first period the workers meet (:meth:`Lockstep.met`): each says hello until every other worker has heard
it and said so, so no period's messages go to a worker the router does not yet know to hear.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

logger = logging.getLogger(__name__)

PATIENCE = 60.0  # wall seconds a worker waits for another's period before going on without it
HELLO = -1  # the period of the steps said while the workers meet


@dataclass
class Peer:
    """Another worker: ``name`` is its first drone (its step key), ``drones`` those it flies."""

    name: str
    drones: frozenset[str]
    left: bool = False
    ended: bool = False  # every flight of it ended, as its newest step said
    heard_us: bool = False  # while meeting: its hello said it heard this worker


@dataclass
class _Period:
    ticks: dict[str, list[tuple[str, str, dict[str, Any]]]] = field(default_factory=dict)  # peer -> messages
    arrived: dict[str, int] = field(default_factory=dict)  # peer -> tick payloads arrived
    steps: dict[str, tuple[int, bool]] = field(default_factory=dict)  # peer -> (ticks put, ended)


class Lockstep:
    """The periods of the other workers as they arrive, kept until this worker takes them. ``me`` is this worker's
    first drone; ``peers`` maps each other worker's first drone to the drones it flies."""

    def __init__(self, me: str, peers: Mapping[str, Iterable[str]], patience: float = PATIENCE) -> None:
        self.me, self.patience = me, patience
        self.peers = {name: Peer(name, frozenset(drones)) for name, drones in peers.items()}
        self.owner = {drone: peer for peer in self.peers.values() for drone in peer.drones}
        self.period = 0  # the period this worker is in
        self._periods: dict[int, _Period] = {}
        self._leaving: set[str] = set()  # said by another thread (the coordinator): taken at the next look

    def owns(self, drone: str) -> bool:
        """True when ``drone`` flies in another worker of this lockstep."""
        return drone in self.owner

    def is_peer(self, name: str) -> bool:
        return name in self.peers

    def tick(self, drone: str, period: int, messages: list[tuple[str, str, dict[str, Any]]]) -> None:
        """A tick of ``drone`` (of another worker) for ``period`` arrived."""
        owner = self.owner[drone]
        if owner.left or period < self.period:  # a worker given up on, or a period gone by: too late
            logger.debug("a tick of %s for period %d came after that period was taken (now %d): dropped", drone,
                         period, self.period)
            return
        peer = owner.name
        kept = self._periods.setdefault(period, _Period())
        kept.ticks.setdefault(peer, []).extend(messages)
        kept.arrived[peer] = kept.arrived.get(peer, 0) + 1

    def step(self, peer: str, period: int, ticks: int, ended: bool, heard: Iterable[str] = ()) -> None:
        """The step of ``peer`` for ``period`` arrived (a hello while meeting)."""
        if period == HELLO:
            self.peers[peer].heard_us = self.me in heard
            return
        if period >= self.period:
            self._periods.setdefault(period, _Period()).steps[peer] = (ticks, ended)

    def leave(self, peer: str) -> None:
        """``peer`` has left (any thread): it is waited for no more."""
        self._leaving.add(peer)

    def missing(self, period: int) -> list[Peer]:
        """The workers whose ticks of ``period`` are not all here yet."""
        while self._leaving:
            name = self._leaving.pop()
            if name in self.peers and not self.peers[name].left:
                self.peers[name].left = True
                logger.warning("the worker flying %s left the fleet: its drones are heard no more",
                               _drones(self.peers[name]))
        kept = self._periods.get(period) or _Period()
        return [p for p in self.peers.values() if not p.left and (
            p.name not in kept.steps or kept.arrived.get(p.name, 0) < kept.steps[p.name][0])]

    def give_up(self, peers: list[Peer]) -> None:
        for peer in peers:
            peer.left = True
            logger.warning("the worker flying %s said nothing for %.0f s: the fleet goes on without it",
                           _drones(peer), self.patience)

    def take(self, period: int) -> list[tuple[str, str, dict[str, Any]]]:
        """Every other worker's messages of ``period`` (the next period begins); their ended flags are noted."""
        kept = self._periods.pop(period, None) or _Period()
        messages: list[tuple[str, str, dict[str, Any]]] = []
        for peer in self.peers.values():
            messages.extend(kept.ticks.get(peer.name, ()))
            if peer.name in kept.steps:
                peer.ended = kept.steps[peer.name][1]
        self.period = period + 1
        return messages

    @property
    def everyone_ended(self) -> bool:
        """Every other worker's flights ended (or it left)."""
        return all(p.left or p.ended for p in self.peers.values())

    def met(self, heard: set[str]) -> bool:
        """True when every other worker was heard (``heard``: the peers whose hello came) and heard this one."""
        return all(p.left or (p.name in heard and p.heard_us) for p in self.peers.values())


def _drones(peer: Peer) -> str:
    names = sorted(peer.drones)
    return ", ".join(names) if len(names) <= 3 else f"{names[0]} … {names[-1]} ({len(names)} drones)"


__all__ = ["HELLO", "PATIENCE", "Lockstep", "Peer"]
