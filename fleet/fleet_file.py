"""The fleet file: the fleet's name, its world, its credentials, and each drone's name, mission, home, seed, shared
predicates and identity.

```yaml
fleet: survey
world: default          # or a world file
vehicle: hexacopter.yaml  # every drone's vehicle profile (docs/vehicles.md); a drone's vehicle: is its own
share: [object, code]   # shared by every drone (each drone may add its own)
credentials: creds      # the fleet's credentials (aeroexec fleet FILE --make-credentials creds); default: made anew
operators: [operator]   # the operators' identities (creds/operator.pem...), who may command the drones
trust: {code: 2}        # a drone believes a code(...) another says only once 2 distinct members say it
drones:
  - {name: d1, mission: missions/figure10.py, home: [0, 0]}
  - {name: d2, mission: missions/square_patrol.yaml, home: [3, 0], seed: 2, share: [position], vehicle: quad.yaml}
  - {name: d3, certificate: /etc/aeroexec/d3.pem, key: /etc/aeroexec/d3.key}   # no mission: it flies elsewhere
```
A drone's identity is its certificate (default ``<credentials>/<name>.pem``, its key beside it as ``.key``); drones
naming one certificate speak with one identity (a process hosting them all). A drone without a mission is a member
that flies in another process or machine. Paths are read from the fleet file's folder, else from the current one
(credentials: from the fleet file's folder). Every problem names file and line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from aeroexec.engine.errors import Problem
from aeroexec.engine.yaml_nodes import NodeReader, line_of
from aeroexec.fleet.access import Roster
from aeroexec.fleet.credentials import CA_CERTIFICATE, OPERATOR, ROUTER, Identity, common_name
from aeroexec.fleet.payloads import NAME_RULE, is_name

TOP = ("fleet", "world", "share", "drones", "token", "telemetry_rate", "credentials", "operators", "trust",
       "vehicle")
PREDICATE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")  # a predicate's name, as a belief writes it
DRONE = ("name", "mission", "home", "seed", "share", "certificate", "key", "vehicle")
RESERVED = ("ca", ROUTER)  # names of the fleet's own credential files


@dataclass(frozen=True)
class DroneSpec:
    name: str
    mission: Path | None  # None: the drone flies elsewhere
    home: tuple[float, float] = (0.0, 0.0)
    seed: int = 0
    share: tuple[str, ...] = ()
    line: int = 0
    certificate: Path | None = None  # its identity's certificate; None: <credentials>/<name>.pem
    key: Path | None = None
    vehicle: Path | None = None  # its vehicle profile (docs/vehicles.md); None: the fleet's, else the simulator's


@dataclass(frozen=True)
class FleetSpec:
    name: str
    drones: tuple[DroneSpec, ...]
    world: Path | None = None  # None: the built-in world
    token: str | None = None
    telemetry_rate: float = 5.0
    file: str = ""
    problems: tuple[Problem, ...] = field(default=())
    credentials: Path | None = None  # the folder of the fleet's credentials; None: made for each run
    operators: tuple[str, ...] = (OPERATOR,)
    trust: dict[str, int] = field(default_factory=dict)  # predicate -> distinct members that must say a belief

    @property
    def flown(self) -> tuple[DroneSpec, ...]:
        """The drones with a mission: those a process running this file flies."""
        return tuple(d for d in self.drones if d.mission is not None)

    def identity_name(self, drone: DroneSpec) -> str:
        """The name of the identity ``drone`` speaks with: its certificate's file name without the suffix."""
        return drone.certificate.stem if drone.certificate is not None else drone.name

    def identity(self, drone: DroneSpec, folder: Path | None = None) -> Identity | None:
        """Where ``drone``'s identity is (in ``folder``, else the file's credentials, unless it names its
        certificate); None if nowhere."""
        folder = folder or self.credentials
        if drone.certificate is None:
            return Identity.at(folder, drone.name) if folder is not None else None
        ca = folder / CA_CERTIFICATE if folder is not None else drone.certificate.parent / CA_CERTIFICATE
        return Identity(drone.certificate, drone.key or drone.certificate.with_suffix(".key"), ca)

    def roster(self) -> Roster:
        """Who speaks for which drone, who may command, and what each drone shares."""
        speakers: dict[str, list[str]] = {}
        for drone in self.drones:
            speakers.setdefault(common_name(self.identity_name(drone), self.name), []).append(drone.name)
        return Roster(self.name, {k: tuple(v) for k, v in speakers.items()},
                      tuple(common_name(o, self.name) for o in self.operators), {d.name: d.share for d in self.drones},
                      (common_name(ROUTER, self.name),), dict(self.trust))


class FleetFileError(ValueError):
    """A fleet file with errors; ``problems`` has every one, with file and line."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problems
        super().__init__("\n".join(str(p) for p in problems))


def load_fleet(path: str | Path) -> FleetSpec:
    """The fleet of the file at ``path``; :class:`FleetFileError` listing every problem when it has errors."""
    path = Path(path)
    r = NodeReader.from_file(path)
    if r.root is None:
        if not r.failed:
            r.error_at(0, "the fleet file is empty")
        raise FleetFileError(r.problems)
    top = r.mapping(r.root, "the fleet file", TOP) or {}
    name = _name(r, top.get("fleet"), r.root, "the fleet's name (fleet:)")
    world = None
    if "world" in top:
        text = r.text(top["world"][1], "world")
        if text and text != "default":
            world = _path(r, path, text, top["world"][1], "the world file")
    common = _names(r, top["share"][1], "share") if "share" in top else ()
    token = r.text(top["token"][1], "token") if "token" in top else None
    credentials = _place(path, r.text(top["credentials"][1], "credentials")) if "credentials" in top else None
    operators = tuple(_checked_names(r, top["operators"][1], "operators")) if "operators" in top else (OPERATOR,)
    rate = r.number(top["telemetry_rate"][1], "telemetry_rate", positive=True) if "telemetry_rate" in top else 5.0
    vehicle = vehicle_of(r, path, top["vehicle"][1]) if "vehicle" in top else None
    drones: list[DroneSpec] = []
    if "drones" not in top:
        r.error(r.root, "the fleet file has no drones: list them under drones:")
    for item in r.sequence(top["drones"][1], "drones") or () if "drones" in top else ():
        drone = _drone(r, path, item, common, drones)
        if drone is not None:
            drones.append(drone if drone.vehicle is not None or vehicle is None else replace(drone, vehicle=vehicle))
    if "drones" in top and not drones and not r.failed:
        r.error(top["drones"][0], "the fleet has no drones")
    for drone in drones:
        if drone.name in operators:
            r.error_at(drone.line, f"the drone {drone.name} has the name of an operator (operators:): an identity "
                                   f"is one or the other")
    trust = _trust(r, top["trust"][1], drones) if "trust" in top else {}
    if r.failed:
        raise FleetFileError(r.problems)
    return FleetSpec(name or "fleet", tuple(drones), world, token, rate or 5.0, str(path), tuple(r.problems),
                     credentials, operators, trust)


def _trust(r: NodeReader, node, drones: list[DroneSpec]) -> dict[str, int]:
    """``trust: {predicate: k}``: each a predicate some drone shares, k from 1 to the drones sharing it less one
    (a drone that shares it hears it from the others only)."""
    entries = r.mapping(node, "trust") or {}
    trust: dict[str, int] = {}
    for predicate, (key_node, value_node) in entries.items():
        if not PREDICATE.match(predicate):
            r.error(key_node, f"trust: {predicate!r} is no predicate's name (letters, digits and _, not a digit "
                              f"first), e.g. trust: {{code: 2}}")
            continue
        sharers = [d.name for d in drones if predicate in d.share]
        if not sharers:
            r.error(key_node, f"trust: no drone shares {predicate} (share:), so no drone hears it from another")
            continue
        needed = r.integer(value_node, f"trust: {predicate}", minimum=1)
        if needed is None:
            continue
        most = max(1, len(sharers) - 1)  # a drone that shares it hears it from the others, never from itself
        if needed > most:
            r.error(value_node, f"trust: {predicate}: {needed} members must agree, but {len(sharers)} drones share "
                                f"it, so a drone that shares it hears it from at most {most}: give 1 to {most}")
            continue
        trust[predicate] = needed
    return trust


def _drone(r: NodeReader, path: Path, node, common: tuple[str, ...], earlier: list[DroneSpec]) -> DroneSpec | None:
    entries = r.mapping(node, "a drone", DRONE)
    if entries is None:
        return None
    failed = r.failed
    name = _name(r, entries.get("name"), node, "a drone's name (name:)")
    if name and any(d.name == name for d in earlier):
        first = next(d for d in earlier if d.name == name)
        r.error(entries["name"][1], f"two drones are called {name} (the first at line {first.line})")
    mission = None
    if "mission" in entries:
        text = r.text(entries["mission"][1], "mission")
        mission = _path(r, path, text, entries["mission"][1], "the mission") if text else None
    home = (0.0, 0.0)
    if "home" in entries:
        items = r.sequence(entries["home"][1], "home") or []
        values = [r.number(i, "home", positive=False) for i in items]
        if len(items) != 2 or None in values:
            r.error(entries["home"][1], f"the home of {name or 'a drone'} must be [east, north] in meters")
        else:
            home = (float(values[0]), float(values[1]))
    seed = r.integer(entries["seed"][1], "seed") if "seed" in entries else len(earlier)
    share = common + tuple(p for p in (_names(r, entries["share"][1], "share") if "share" in entries else ())
                           if p not in common)
    if name in RESERVED:
        r.error(entries["name"][1], f"the drone name {name} is reserved for the fleet's credentials ({name}.pem)")
    certificate = _place(path, r.text(entries["certificate"][1], "certificate")) if "certificate" in entries else None
    key = _place(path, r.text(entries["key"][1], "key")) if "key" in entries else None
    if key is not None and certificate is None:
        r.error(entries["key"][1], f"the drone {name or '?'} names a key without its certificate: give certificate:")
    if certificate is not None and (not is_name(certificate.stem) or certificate.stem in RESERVED):
        r.error(entries["certificate"][1], f"the certificate's file name {certificate.stem!r} names its identity: it "
                                           f"{NAME_RULE}, and is not {' or '.join(RESERVED)}")
    vehicle = vehicle_of(r, path, entries["vehicle"][1]) if "vehicle" in entries else None
    if r.failed and not failed or not name or "mission" in entries and mission is None:
        return None
    return DroneSpec(name, mission, home, seed or 0, share, line_of(node), certificate, key, vehicle)


def vehicle_of(r: NodeReader, fleet_file: Path, node) -> Path | None:
    """The vehicle profile a ``vehicle:`` names, found and read (its problems name its own file and line)."""
    text = r.text(node, "vehicle")
    found = _path(r, fleet_file, text, node, "the vehicle profile") if text else None
    if found is not None:
        from aeroexec.drones.profile import VehicleProfileError, load_vehicle_profile

        try:
            load_vehicle_profile(str(found))
        except VehicleProfileError as error:
            r.error(node, f"vehicle: {error}")
            return None
    return found


def _name(r: NodeReader, entry, node, what: str) -> str | None:
    if entry is None:
        r.error(node, f"{what} is missing")
        return None
    text = r.text(entry[1], what)
    if text is not None and not is_name(text):
        r.error(entry[1], f"{what} {text!r} {NAME_RULE}")
        return None
    return text


def _names(r: NodeReader, node, what: str) -> tuple[str, ...]:
    return tuple(name for name, _ in r.names(node, what))


def _checked_names(r: NodeReader, node, what: str) -> list[str]:
    names = []
    for name, item in r.names(node, what):
        if not is_name(name) or name in RESERVED:
            r.error(item, f"{what}: {name!r} {NAME_RULE}, and is not {' or '.join(RESERVED)}")
        else:
            names.append(name)
    return names


def _place(fleet_file: Path, text: str | None) -> Path | None:
    """A path the fleet file names, from the fleet file's folder (it need not exist yet)."""
    return None if not text else fleet_file.parent / text


def _path(r: NodeReader, fleet_file: Path, text: str, node, what: str) -> Path | None:
    for candidate in (fleet_file.parent / text, Path(text)):
        try:
            if candidate.is_file():
                return candidate
        except (OSError, ValueError) as error:  # a name too long, a NUL byte...
            r.error(node, f"{what} {text[:200]} cannot be a file: {getattr(error, 'strerror', None) or error}")
            return None
    r.error(node, f"{what} {text} is not found (next to the fleet file, nor from the current folder)")
    return None
