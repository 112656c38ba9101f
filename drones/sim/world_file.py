"""The YAML world file format: parse and check it, naming ``file:line`` in every error.

The file is read as a YAML node tree (PyYAML keeps each node's position), then checked key by key into
the records of :mod:`aeroexec.drones.sim.world`. Example: ``default_world.yaml`` next to this module.

Keys (ENU meters from home, angles in degrees; ``?`` = optional)::

    name?: text
    home: {lat, lon, alt}                      # alt in m AMSL
    bounds: {min: [x, y, z], max: [x, y, z]}   # the geofence; must contain home (0, 0, 0)
    obstacles?: - {type: box, center: [x, y, z], size: [sx, sy, sz], name?}
                - {type: cylinder, center: [x, y], radius, height, base?: 0, name?}
    markers?: - {id: 0..1023, position: [x, y, z], yaw?: 0, pitch?: 0, name?: marker_<id>}
    objects?: - {name, color, shape, position: [x, y, z]}
    platform?: {path: [[x, y, z], ...], speed, loop?: true, name?: platform, marker_id?, deck_radius?: 0.75}
    camera?: {hfov?: 80, vfov?: 60, range?: 12, pitch?: -20}
    payload?: [name, ...]                      # items the drone carries; a dropped one lands as an object

Names are unique across obstacles, markers, objects, the platform and the payload; marker ids are unique.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

from aeroexec.drones.sim.shapes import Box, Cylinder, Obstacle
from aeroexec.drones.sim.world import (
    DECK_RADIUS,
    Bounds,
    CameraSettings,
    Marker,
    Platform,
    World,
    WorldError,
    WorldObject,
)

from aeroexec.lazy import lazy_module
from aeroexec.limits import InputError, compose_yaml, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    import yaml
    from yaml.nodes import Node
else:  # PyYAML is imported when a world file is read, not with this module (a world kept parsed reads none)
    yaml = lazy_module("yaml")

Vector = tuple[float, float, float]

MAX_MARKER_ID = 1023  # ArUco's original dictionary has 1024 markers: ids 0..1023

_TOP_KEYS = {"name", "home", "bounds", "obstacles", "markers", "objects", "platform", "camera", "payload"}


class _Reader:
    """Typed access to YAML nodes, raising ``WorldError('file:line: message')``."""

    def __init__(self, source: str) -> None:
        self.source = source
        self._constructor = yaml.constructor.SafeConstructor()

    def error(self, node: Node | None, message: str) -> WorldError:
        if node is None:
            return WorldError(f"{self.source}: {message}")
        return WorldError(f"{self.source}:{node.start_mark.line + 1}: {message}")

    def mapping(self, node: Node, what: str, required: set[str], optional: set[str]) -> dict[str, Node]:
        if not isinstance(node, yaml.nodes.MappingNode):
            raise self.error(node, f"{what} must be a mapping of keys to values")
        out: dict[str, Node] = {}
        allowed = required | optional
        for key_node, value_node in node.value:
            key = self.scalar(key_node, f"a key of {what}")
            if not isinstance(key, str):
                raise self.error(key_node, f"{what} has a key {key!r} that is not a name")
            if key not in allowed:
                expected = ", ".join(sorted(allowed))
                raise self.error(key_node, f"unknown key '{key}' in {what} (expected one of: {expected})")
            if key in out:
                raise self.error(key_node, f"duplicate key '{key}' in {what}")
            out[key] = value_node
        missing = sorted(required - out.keys())
        if missing:
            raise self.error(node, f"{what} misses the key '{missing[0]}'")
        return out

    def sequence(self, node: Node, what: str) -> list[Node]:
        if not isinstance(node, yaml.nodes.SequenceNode):
            raise self.error(node, f"{what} must be a list")
        return list(node.value)

    def scalar(self, node: Node, what: str) -> object:
        if not isinstance(node, yaml.nodes.ScalarNode):
            kind = "list" if isinstance(node, yaml.nodes.SequenceNode) else "mapping"
            raise self.error(node, f"{what} must be a single value, not a {kind}")
        try:
            return self._constructor.construct_object(node, deep=True)
        except (yaml.constructor.ConstructorError, ValueError) as exc:
            raise self.error(node, f"{what} is not a valid value: {exc}") from None

    def number(self, node: Node, what: str, *, minimum: float | None = None, positive: bool = False,
               maximum: float | None = None) -> float:
        value = self.scalar(node, what)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(node, f"{what} must be a number, not {value!r}")
        try:
            value = float(value)
        except OverflowError:  # an integer too large for a float
            value = math.inf
        if not math.isfinite(value):
            raise self.error(node, f"{what} must be a finite number, not {value}")
        if positive and value <= 0.0:
            raise self.error(node, f"{what} must be positive, not {value:g}")
        if minimum is not None and value < minimum:
            raise self.error(node, f"{what} must be at least {minimum:g}, not {value:g}")
        if maximum is not None and value > maximum:
            raise self.error(node, f"{what} must be at most {maximum:g}, not {value:g}")
        return value

    def integer(self, node: Node, what: str, low: int, high: int) -> int:
        value = self.scalar(node, what)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(node, f"{what} must be an integer, not {value!r}")
        if not low <= value <= high:
            raise self.error(node, f"{what} must be between {low} and {high}, not {value}")
        return value

    def string(self, node: Node, what: str) -> str:
        value = self.scalar(node, what)
        if not isinstance(value, str) or not value.strip():
            raise self.error(node, f"{what} must be a non-empty text, not {value!r}")
        return value.strip()

    def boolean(self, node: Node, what: str) -> bool:
        value = self.scalar(node, what)
        if not isinstance(value, bool):
            raise self.error(node, f"{what} must be true or false, not {value!r}")
        return value

    def vector(self, node: Node, what: str, size: int = 3) -> tuple[float, ...]:
        items = self.sequence(node, what)
        if len(items) != size:
            raise self.error(node, f"{what} must have {size} numbers, not {len(items)}")
        return tuple(self.number(item, f"{what}[{i}]") for i, item in enumerate(items))


class _WorldParser:
    def __init__(self, source: str) -> None:
        self.r = _Reader(source)
        self.names: dict[str, int] = {}  # name -> line where it was first given

    def unique(self, node: Node, name: str) -> str:
        if name in self.names:
            raise self.r.error(node, f"duplicate name '{name}' (first used on line {self.names[name]})")
        self.names[name] = node.start_mark.line + 1
        return name

    def world(self, root: Node) -> World:
        r = self.r
        keys = r.mapping(root, "the world", {"home", "bounds"}, _TOP_KEYS - {"home", "bounds"})
        home = self.home(keys["home"])
        bounds = self.bounds(keys["bounds"])
        if not bounds.contains((0.0, 0.0, 0.0)):
            raise r.error(keys["bounds"], "the bounds must contain the home point (0, 0, 0)")
        obstacles = tuple(self.obstacle(n, i) for i, n in self.items(keys, "obstacles"))
        for node, obstacle in zip(self.item_nodes(keys, "obstacles"), obstacles, strict=True):
            if obstacle.signed_distance((0.0, 0.0, 0.0)) <= 0.0:
                raise r.error(node, f"obstacle '{obstacle.name}' covers the home point (0, 0, 0)")
        ids: dict[int, int] = {}  # marker id -> line where it was first given
        markers = tuple(self.marker(n, i, ids) for i, n in self.items(keys, "markers"))
        objects = tuple(self.object(n, i) for i, n in self.items(keys, "objects"))
        platform = self.platform(keys["platform"], ids) if "platform" in keys else None
        camera = self.camera(keys["camera"]) if "camera" in keys else CameraSettings()
        name = r.string(keys["name"], "the world's name") if "name" in keys else "world"
        payload = tuple(self.unique(n, r.string(n, f"payload item {i + 1}")) for i, n in self.items(keys, "payload"))
        return World(home=home, bounds=bounds, obstacles=obstacles, markers=markers, objects=objects,
                     platform=platform, camera=camera, payload=payload, name=name, source=r.source)

    def item_nodes(self, keys: dict[str, Node], key: str) -> list[Node]:
        return self.r.sequence(keys[key], f"'{key}'") if key in keys else []

    def items(self, keys: dict[str, Node], key: str) -> Iterator[tuple[int, Node]]:
        return enumerate(self.item_nodes(keys, key))

    def home(self, node: Node) -> tuple[float, float, float]:
        k = self.r.mapping(node, "home", {"lat", "lon", "alt"}, set())
        return (self.r.number(k["lat"], "home lat", minimum=-90.0, maximum=90.0),
                self.r.number(k["lon"], "home lon", minimum=-180.0, maximum=180.0),
                self.r.number(k["alt"], "home alt"))

    def bounds(self, node: Node) -> Bounds:
        k = self.r.mapping(node, "bounds", {"min", "max"}, set())
        lower = self.r.vector(k["min"], "bounds min")
        upper = self.r.vector(k["max"], "bounds max")
        for axis, lo, hi in zip("xyz", lower, upper, strict=True):
            if hi <= lo:
                raise self.r.error(node, f"bounds max {axis} ({hi:g}) must be above min {axis} ({lo:g})")
        return Bounds(lower, upper)  # type: ignore[arg-type]

    def obstacle(self, node: Node, index: int) -> Obstacle:
        r = self.r
        what = f"obstacle {index + 1}"
        if not isinstance(node, yaml.nodes.MappingNode):
            raise r.error(node, f"{what} must be a mapping")
        kinds = [v for k, v in node.value if isinstance(k, yaml.nodes.ScalarNode) and k.value == "type"]
        kind = r.string(kinds[0], f"the type of {what}") if kinds else None
        if kind == "box":
            k = r.mapping(node, what, {"type", "center", "size"}, {"name"})
            name = (self.unique(k["name"], r.string(k["name"], f"the name of {what}"))
                    if "name" in k else f"box_{index + 1}")
            size = r.vector(k["size"], f"the size of {what}")
            for i, s in enumerate(size):
                if s <= 0.0:
                    raise r.error(k["size"], f"the size of {what} must be positive, not {s:g} (size[{i}])")
            return Box(name, r.vector(k["center"], f"the center of {what}"), size)  # type: ignore[arg-type]
        if kind == "cylinder":
            k = r.mapping(node, what, {"type", "center", "radius", "height"}, {"name", "base"})
            name = (self.unique(k["name"], r.string(k["name"], f"the name of {what}"))
                    if "name" in k else f"cylinder_{index + 1}")
            return Cylinder(
                name,
                r.vector(k["center"], f"the center of {what} (x, y)", size=2),  # type: ignore[arg-type]
                r.number(k["radius"], f"the radius of {what}", positive=True),
                r.number(k["height"], f"the height of {what}", positive=True),
                r.number(k["base"], f"the base of {what}") if "base" in k else 0.0,
            )
        where = kinds[0] if kinds else node
        raise r.error(where, f"{what} needs a type: box or cylinder" + (f", not '{kind}'" if kind else ""))

    def marker(self, node: Node, index: int, ids: dict[int, int]) -> Marker:
        r = self.r
        what = f"marker {index + 1}"
        k = r.mapping(node, what, {"id", "position"}, {"yaw", "pitch", "name"})
        marker_id = r.integer(k["id"], f"the id of {what}", 0, MAX_MARKER_ID)
        if marker_id in ids:
            raise r.error(k["id"], f"duplicate marker id {marker_id} (first used on line {ids[marker_id]})")
        ids[marker_id] = k["id"].start_mark.line + 1
        name = r.string(k["name"], f"the name of {what}") if "name" in k else f"marker_{marker_id}"
        self.unique(k.get("name", k["id"]), name)
        return Marker(
            id=marker_id,
            position=r.vector(k["position"], f"the position of {what}"),  # type: ignore[arg-type]
            yaw=r.number(k["yaw"], f"the yaw of {what}") if "yaw" in k else 0.0,
            pitch=r.number(k["pitch"], f"the pitch of {what}", minimum=-90.0, maximum=90.0) if "pitch" in k else 0.0,
            name=name,
        )

    def object(self, node: Node, index: int) -> WorldObject:
        r = self.r
        what = f"object {index + 1}"
        k = r.mapping(node, what, {"name", "color", "shape", "position"}, set())
        return WorldObject(
            name=self.unique(k["name"], r.string(k["name"], f"the name of {what}")),
            color=r.string(k["color"], f"the color of {what}").lower(),
            shape=r.string(k["shape"], f"the shape of {what}").lower(),
            position=r.vector(k["position"], f"the position of {what}"),  # type: ignore[arg-type]
        )

    def platform(self, node: Node, marker_ids: dict[int, int]) -> Platform:
        r = self.r
        k = r.mapping(node, "the platform", {"path", "speed"}, {"name", "loop", "marker_id", "deck_radius"})
        name = self.unique(k["name"], r.string(k["name"], "the platform's name")) if "name" in k else "platform"
        path = tuple(r.vector(p, f"point {i + 1} of the platform's path")
                     for i, p in enumerate(r.sequence(k["path"], "the platform's path")))
        if not path:
            raise r.error(k["path"], "the platform's path needs at least one point")
        marker_id = None
        if "marker_id" in k:
            marker_id = r.integer(k["marker_id"], "the platform's marker_id", 0, MAX_MARKER_ID)
            if marker_id in marker_ids:
                first = marker_ids[marker_id]
                raise r.error(k["marker_id"], f"duplicate marker id {marker_id} (first used on line {first})")
        return Platform(
            name=name,
            path=path,  # type: ignore[arg-type]
            speed=r.number(k["speed"], "the platform's speed", minimum=0.0),
            loop=r.boolean(k["loop"], "the platform's loop") if "loop" in k else True,
            marker_id=marker_id,
            deck_radius=(r.number(k["deck_radius"], "the platform's deck_radius", positive=True)
                         if "deck_radius" in k else DECK_RADIUS),
        )

    def camera(self, node: Node) -> CameraSettings:
        r = self.r
        k = r.mapping(node, "camera", set(), {"hfov", "vfov", "range", "pitch"})
        d = CameraSettings()
        return CameraSettings(
            hfov=r.number(k["hfov"], "camera hfov", positive=True, maximum=179.0) if "hfov" in k else d.hfov,
            vfov=r.number(k["vfov"], "camera vfov", positive=True, maximum=179.0) if "vfov" in k else d.vfov,
            range=r.number(k["range"], "camera range", positive=True) if "range" in k else d.range,
            pitch=r.number(k["pitch"], "camera pitch", minimum=-90.0, maximum=90.0) if "pitch" in k else d.pitch,
        )


def parse_world(text: str, source: str = "<world>") -> World:
    """A :class:`World` from YAML ``text``; ``source`` names the file in error messages."""
    try:
        root = compose_yaml(text, source)
    except InputError as exc:
        raise WorldError(str(exc)) from None
    if root is None:
        raise WorldError(f"{source}:1: the world file is empty")
    return _WorldParser(source).world(root)


def load_world(path: str | Path) -> World:
    """Read a YAML world file; raises :class:`WorldError` naming ``file:line`` on any mistake.

    A world read without errors is kept parsed (a :class:`World` is immutable): in this process, and in the user's
    private cache folder (:mod:`aeroexec.cache`) keyed by the file's name and bytes and the reading code, so the
    next command reads no YAML for it (``aeroexec verify`` asks for its world more than once; PyYAML alone is
    ~15 ms of a start). A file with errors is never kept: it is read, and refused, every time."""
    try:
        text = read_text(path, what="the world file")
    except InputError as exc:
        raise WorldError(str(exc)) from None
    key = _world_key(text, str(path))
    world = _parsed.get(key) or _kept_world(key)
    if world is None:
        world = parse_world(text, str(path))  # raises WorldError: nothing is kept
        _keep_world(key, world)
    if len(_parsed) >= _PARSED_IN_PROCESS:
        _parsed.clear()
    _parsed[key] = world
    return world


#: The worlds parsed in this process, by :func:`_world_key`, and the most kept.
_parsed: dict[str, World] = {}
_PARSED_IN_PROCESS = 16


def _world_key(text: str, source: str) -> str:
    """A hash of a world file's name and text, of the sizes and times of the modules that read it and make its
    records (as a cached catalog's key has them: their files are not read again at every start), and of the versions
    of aeroexec and Python: a changed reader never serves a world another one parsed."""
    import os
    import sys

    from aeroexec.drones.sim import geofence, shapes, world

    import aeroexec
    from aeroexec.cache import sha256

    stamp = [source, aeroexec.__version__, sys.version_info[:2]]
    for module in (world, shapes, geofence, sys.modules[__name__]):
        try:
            info = os.stat(module.__file__ or "")
            stamp.append((module.__name__, info.st_size, info.st_mtime_ns))
        except OSError:
            stamp.append(f"{module.__name__}: unread")
    digest = sha256(repr(stamp).encode() + b"\0")
    return digest.hexdigest()[:32] + sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:32]


def _kept_world(key: str) -> World | None:
    """The world kept under ``key`` in the user's cache folder; None when there is none or it cannot be read."""
    from aeroexec.cache import kept, unpickled

    data = kept(f"world.{key}.pickle")
    if data is None:
        return None
    try:
        world = unpickled(data)
    except Exception:  # noqa: BLE001 (a torn or stale file: the world is parsed again and the file rewritten)
        return None
    return world if isinstance(world, World) else None


def _keep_world(key: str, world: World) -> None:
    """Keep ``world`` under ``key`` in the user's cache folder (a folder that cannot be written is no error)."""
    import pickle

    from aeroexec.cache import keep

    try:
        data = pickle.dumps(world, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, TypeError, AttributeError):
        return
    keep(f"world.{key}.pickle", data)


def default_world() -> World:
    """The world that ships with the package (``default_world.yaml``): a 40 x 40 x 20 m field."""
    return load_world(Path(__file__).with_name("default_world.yaml"))
