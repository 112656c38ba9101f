"""Who may say what in a fleet: its roster, and the Zenoh access-control rules its router enforces from it.

The roster names each identity (a certificate's common name) and the drones it speaks for: one drone, or every
drone of a process that hosts several. The router gives each identity the right to publish on its own drones'
keys (``aeroexec/<fleet>/<drone>/tick``) and to answer their command queries, nowhere else; operators may query the
``command`` keys (one drone's, or every drone's with ``*/command``, which reaches every member serving one); every
identity may subscribe to the fleet's keys; the fleet's other routers (the router identity, linking machines) relay
everything of the fleet. Anything else is denied, by the router, before it reaches
anyone. Receivers use the roster too: who is a member, which predicates each drone shares, and how many members
must agree on a belief of a predicate the fleet file's ``trust:`` names.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

SPOKEN = ("tick",)  # what a drone publishes (a worker process of the fleet's own puts steps as its router)
RELAYED = ["put", "declare_subscriber", "declare_queryable", "query", "reply"]  # between the fleet's routers


@dataclass(frozen=True)
class Roster:
    """The identities of ``fleet``: ``speakers`` (identity -> the drones it speaks for), ``operators`` (identities
    that may command), ``shares`` (drone -> the predicates it shares with the fleet), ``routers`` (the identities
    of the fleet's routers, which relay for each other), ``trust`` (predicate -> how many distinct members must
    say a belief of it before a drone believes it; 1 when not named)."""

    fleet: str
    speakers: Mapping[str, tuple[str, ...]]
    operators: tuple[str, ...] = ()
    shares: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    routers: tuple[str, ...] = ()
    trust: Mapping[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        owners: dict[str, str] = {}
        for identity, drones in self.speakers.items():
            if identity in self.operators:
                raise ValueError(f"the identity {identity} is both an operator and a drone's")
            for drone in drones:
                if drone in owners and owners[drone] != identity:
                    raise ValueError(f"the drone {drone} has two identities: {owners[drone]} and {identity}")
                owners[drone] = identity
        object.__setattr__(self, "_drones", frozenset(owners))

    @property
    def drones(self) -> frozenset[str]:
        """Every drone of the fleet, wherever it flies."""
        return self._drones  # type: ignore[attr-defined]

    def needed(self, predicate: str) -> int:
        """How many distinct members must say a belief of ``predicate`` before a drone believes it."""
        return self.trust.get(predicate, 1)

    def shared_by(self, drone: str) -> tuple[str, ...]:
        """The predicates ``drone`` shares (empty when it shares none, or is no member)."""
        return tuple(self.shares.get(drone, ()))


def access_control(roster: Roster) -> dict[str, Any]:
    """Zenoh's ``access_control`` configuration for the router of ``roster``'s fleet (default: deny)."""
    prefix = f"aeroexec/{roster.fleet}"
    rules: list[dict[str, Any]] = [
        _rule("hear", "ingress", ["declare_subscriber"], [f"{prefix}/**"]),
        # the others' subscribers too: a declared publisher sends only where someone listens
        _rule("heard", "egress", ["put", "declare_subscriber"], [f"{prefix}/**"]),
        _rule("command", "ingress", ["query"], [f"{prefix}/*/command"]),
        _rule("answered", "egress", ["reply", "declare_queryable"], [f"{prefix}/*/command"]),
        # an operator's query of every drone (``*/command``) reaches each member; a member answers only on its
        # own drones' keys (``serve``): the rule naming a member's own keys only let a fleet-wide query reach none
        _rule("asked", "egress", ["query"], [f"{prefix}/*/command"]),
        _rule("relay", "ingress", RELAYED, [f"{prefix}/**"]),
        _rule("relayed", "egress", RELAYED, [f"{prefix}/**"]),
    ]
    subjects: list[dict[str, Any]] = []
    policies: list[dict[str, Any]] = []
    everyone = []
    for n, (identity, drones) in enumerate(sorted(roster.speakers.items())):
        own = sorted(drones)
        if not own:
            continue
        rules += [
            _rule(f"speak-{n}", "ingress", ["put"], [f"{prefix}/{d}/{topic}" for d in own for topic in SPOKEN]),
            _rule(f"serve-{n}", "ingress", ["declare_queryable", "reply"], [f"{prefix}/{d}/command" for d in own]),
        ]
        subjects.append({"id": f"member-{n}", "cert_common_names": [identity]})
        policies.append({"rules": [f"speak-{n}", f"serve-{n}", "asked"], "subjects": [f"member-{n}"]})
        everyone.append(f"member-{n}")
    if roster.operators:
        subjects.append({"id": "operators", "cert_common_names": sorted(roster.operators)})
        policies.append({"rules": ["command", "answered"], "subjects": ["operators"]})
        everyone.append("operators")
    if roster.routers:
        subjects.append({"id": "routers", "cert_common_names": sorted(roster.routers)})
        policies.append({"rules": ["relay", "relayed"], "subjects": ["routers"]})
    if everyone:
        policies.append({"rules": ["hear", "heard"], "subjects": everyone})
    return {"enabled": True, "default_permission": "deny", "rules": rules, "subjects": subjects,
            "policies": policies}


def _rule(name: str, flow: str, messages: list[str], keys: list[str]) -> dict[str, Any]:
    return {"id": name, "permission": "allow", "flows": [flow], "messages": messages, "key_exprs": keys}
