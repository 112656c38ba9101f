"""The fleet file: the fleet's name, its world, and each drone's name, mission, home, seed and shared predicates.

```yaml
fleet: survey
world: default          # or a world file
share: [object, code]   # shared by every drone (each drone may add its own)
drones:
  - {name: d1, mission: missions/figure10.py, home: [0, 0]}
  - {name: d2, mission: missions/square_patrol.yaml, home: [3, 0], seed: 2, share: [position]}
```
Paths are read from the fleet file's folder, else from the current one. Every problem names file and line.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.engine.errors import Problem
from aeroexec.engine.yaml_nodes import NodeReader, line_of
from aeroexec.fleet.payloads import NAME

TOP = ("fleet", "world", "share", "drones", "token", "telemetry_rate")
DRONE = ("name", "mission", "home", "seed", "share")


@dataclass(frozen=True)
class DroneSpec:
    name: str
    mission: Path
    home: tuple[float, float] = (0.0, 0.0)
    seed: int = 0
    share: tuple[str, ...] = ()
    line: int = 0


@dataclass(frozen=True)
class FleetSpec:
    name: str
    drones: tuple[DroneSpec, ...]
    world: Path | None = None  # None: the built-in world
    token: str | None = None
    telemetry_rate: float = 5.0
    file: str = ""
    problems: tuple[Problem, ...] = field(default=())


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
    rate = r.number(top["telemetry_rate"][1], "telemetry_rate", positive=True) if "telemetry_rate" in top else 5.0
    drones: list[DroneSpec] = []
    if "drones" not in top:
        r.error(r.root, "the fleet file has no drones: list them under drones:")
    for item in r.sequence(top["drones"][1], "drones") or () if "drones" in top else ():
        drone = _drone(r, path, item, common, drones)
        if drone is not None:
            drones.append(drone)
    if "drones" in top and not drones and not r.failed:
        r.error(top["drones"][0], "the fleet has no drones")
    if r.failed:
        raise FleetFileError(r.problems)
    return FleetSpec(name or "fleet", tuple(drones), world, token, rate or 5.0, str(path), tuple(r.problems))


def _drone(r: NodeReader, path: Path, node, common: tuple[str, ...], earlier: list[DroneSpec]) -> DroneSpec | None:
    entries = r.mapping(node, "a drone", DRONE)
    if entries is None:
        return None
    failed = r.failed
    name = _name(r, entries.get("name"), node, "a drone's name (name:)")
    if name and any(d.name == name for d in earlier):
        first = next(d for d in earlier if d.name == name)
        r.error(entries["name"][1], f"two drones are called {name} (the first at line {first.line})")
    if "mission" not in entries:
        r.error(node, f"the drone {name or '?'} has no mission: give mission: FILE")
        mission = None
    else:
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
    if r.failed and not failed or not name or mission is None:
        return None
    return DroneSpec(name, mission, home, seed or 0, share, line_of(node))


def _name(r: NodeReader, entry, node, what: str) -> str | None:
    if entry is None:
        r.error(node, f"{what} is missing")
        return None
    text = r.text(entry[1], what)
    if text is not None and (not NAME.match(text) or text == "self"):
        r.error(entry[1], f"{what} {text!r} must start with a letter and hold only letters, digits and _, "
                          f"and cannot be self")
        return None
    return text


def _names(r: NodeReader, node, what: str) -> tuple[str, ...]:
    return tuple(name for name, _ in r.names(node, what))


def _path(r: NodeReader, fleet_file: Path, text: str, node, what: str) -> Path | None:
    for candidate in (fleet_file.parent / text, Path(text)):
        if candidate.is_file():
            return candidate
    r.error(node, f"{what} {text} is not found (next to the fleet file, nor from the current folder)")
    return None
