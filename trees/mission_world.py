"""The world a mission is verified and flown in: where it is planned, at real scale.

- A world file (``--world``) is used as it is; ``--home`` moves it to that home.
- A mission that says where it is (a plan's ``plannedHomePosition``, a waypoint file's home line, or its first
  item's place) flies in an open field generated around it (:func:`aeroexec.drones.sim.open_field.open_field`):
  the mission's places plus a margin, its geofence as the world's fences; ``--home`` places the field's home (the
  take-off point) elsewhere, the items keep their latitudes and longitudes.
- A mission written for another system's world (an Aerostack2 script or tree, written for Gazebo's empty world)
  flies in open ground like that world: a flat, obstacle-free field around the default world's home, or at the
  GPS origin the mission names (``set_origin``, ``SetOrigin``, its first GPS point), as a plan flies at its home.
  The dialects say which missions these are (entry-point group :data:`MISSION_GROUNDS`: :class:`MissionGround`);
  one that needs the default field (its markers, its obstacles) is not among them.
- A mission in local meters (Python, behavior trees, TML) keeps the default world (moved to ``--home`` if given).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from pathlib import Path

from aeroexec.drones.geodesy import Geodetic, geo_to_enu
from aeroexec.drones.sim.geofence import Fence
from aeroexec.drones.sim.world import Frame
from aeroexec.trees.items.readers import is_item_file, load_item_mission

from aeroexec.plugins import installed_plugins

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # the items' records are imported for a mission planned on a map, not for every world
    from typing import Any

    from aeroexec.trees.items.model import ItemMission

logger = logging.getLogger(__name__)

#: The entry-point group of readers of the ground a mission was written for: ``(path) -> MissionGround | None``
#: (None: not theirs, or a mission for the default field).
MISSION_GROUNDS = "aeroexec.mission_grounds"
#: Meters of open ground around the home (at the least) for a mission written for another system's world.
OPEN_REACH = 100.0
#: Meters above the home the open ground reaches up to (at the least).
OPEN_CEILING = 50.0


@dataclass(frozen=True)
class MissionGround:
    """Where a mission written for another system's world flies: ``written_for`` ("Gazebo's empty world"), the
    GPS ``origin`` it names (None: the default world's home), the ``places`` it names (ENU meters from there), and
    the named ``frames`` of that world (:class:`~aeroexec.drones.sim.world.Frame`: its models, placed by the
    simulator's world config the mission's project keeps, ``config`` that file) and where it spawns the drones it
    names (``starts``: east, north meters from the home)."""

    written_for: str
    origin: Geodetic | None = None
    places: tuple[tuple[float, float, float], ...] = ()
    frames: tuple[Frame, ...] = ()
    config: str | None = None
    starts: tuple[tuple[str, tuple[float, float]], ...] = ()


def mission_ground(mission: Path) -> MissionGround | None:
    """The ground ``mission`` was written for, as the first dialect that knows it says; None when none does."""
    for origin, reader in installed_plugins(MISSION_GROUNDS):
        try:
            ground = reader(Path(mission))
        except Exception as exc:  # a broken reader is reported, never takes the run down
            logger.error("%s cannot read the ground of %s: %s", origin, mission, exc)
            continue
        if ground is not None:
            return ground
    return None


def ground_world(ground: MissionGround, home: Geodetic | None = None) -> Any:
    """Open ground like the world ``ground`` names: a flat field at ``home`` (default: its origin, else the default
    world's home), :data:`OPEN_REACH` meters around it at the least."""
    from aeroexec.drones.sim import default_world
    from aeroexec.drones.sim.open_field import open_field

    if home is None:
        home = ground.origin or default_world().home
    elif len(home) == 2 or home[2] is None:
        home = (home[0], home[1], ground.origin[2] if ground.origin is not None else 0.0)
    reach = [(-OPEN_REACH, -OPEN_REACH, 0.0), (OPEN_REACH, OPEN_REACH, OPEN_CEILING)]
    written_for = ground.written_for + (f", {ground.config}" if ground.config else "")
    starts = [(e, n, 0.0) for _, (e, n) in ground.starts]
    world = open_field(home, [*ground.places, *(f.position for f in ground.frames), *starts, *reach],
                       name=f"open ground at {home[0]:.5f}, {home[1]:.5f} (as {written_for})")
    if ground.frames or ground.starts:
        world = dataclasses.replace(world, frames=ground.frames, starts=ground.starts)
    return world


#: Items besides the positional ones whose altitude is flown at (a take-off's, a change of altitude's).
_HEIGHT_COMMANDS = (22, 113)
GRIPPER_LOAD = "gripper_load"  # what the drone of a mission that opens its gripper carries


def _fences(mission: ItemMission, home: Geodetic) -> list[Fence]:
    found = []
    for fence in mission.fences:
        if fence.center is not None:
            center = geo_to_enu((*fence.center, 0.0), home)[:2]
            found.append(Fence(fence.inclusion, center=center, radius=fence.radius, line=fence.line))
        else:
            vertices = tuple(geo_to_enu((lat, lon, 0.0), home)[:2] for lat, lon in fence.vertices)
            found.append(Fence(fence.inclusion, vertices, line=fence.line))
    return found


def mission_places(mission: ItemMission, home: Geodetic) -> list[tuple[float, float, float]]:
    """Every place the mission flies to or names, ENU meters from ``home`` (altitudes above home)."""
    from aeroexec.trees.items.model import ABSOLUTE_FRAMES, GLOBAL_FRAMES, MISSION_FRAME, POSITIONAL

    heights = {*POSITIONAL, *_HEIGHT_COMMANDS}
    places = []
    top = 0.0
    for item in mission.items:
        if item.command in heights and item.frame in (*GLOBAL_FRAMES, MISSION_FRAME) and \
                not math.isnan(item.altitude):
            alt = item.altitude - (home[2] if item.frame in ABSOLUTE_FRAMES else 0.0)
            top = max(top, alt)
        else:
            alt = 0.0
        if item.command in POSITIONAL and item.has_position() and -90 <= item.latitude <= 90 and \
                -180 <= item.longitude <= 180:
            places.append(geo_to_enu((item.latitude, item.longitude, max(alt, 0.0)), home))
    places += [geo_to_enu(point, home) for point, _ in mission.rally]
    places.append((0.0, 0.0, top))
    return places


def world_for(mission: ItemMission, home: Geodetic | None = None) -> Any:
    """The open field around ``mission`` at ``home`` (default: the mission's own home); None when the mission
    names no place on Earth."""
    from aeroexec.drones.sim.open_field import open_field
    from aeroexec.trees.items.behaviors import mission_home  # here: only a mission planned on a map needs it

    own = mission_home(mission)
    if home is None:
        home = own
    elif len(home) == 2 or home[2] is None:
        home = (home[0], home[1], own[2] if own is not None else 0.0)
    if home is None:
        return None
    payload = (GRIPPER_LOAD,) if any(i.command == 211 and i.params[1] == 0 for i in mission.items) else ()
    return open_field(home, mission_places(mission, home), _fences(mission, home), payload)


def mission_world(mission: Path | None, world_file: str | None = None, home: Geodetic | None = None,
                  default: bool = True) -> Any:
    """The world ``mission`` is verified and flown in (see the module's docstring); None when there is none
    (``default`` False, no world file and a mission in local meters)."""
    from aeroexec.drones.sim import default_world, load_world

    if world_file:
        world = load_world(world_file)  # a WorldError says why it cannot be read
        if home is not None:
            world = dataclasses.replace(world, home=(home[0], home[1], home[2] if home[2] is not None
                                                     else world.home[2]))
        if mission is not None and is_item_file(mission):
            from aeroexec.trees.model import TreeFormatError  # here: only an item mission needs the tree model

            try:
                fences = _fences(load_item_mission(mission), world.home)
            except TreeFormatError:
                fences = []  # the mission's check says why it cannot be read
            if fences:
                world = dataclasses.replace(world, fences=(*world.fences, *fences))
        return world
    if mission is not None and is_item_file(mission):
        from aeroexec.trees.model import TreeFormatError

        try:
            generated = world_for(load_item_mission(mission), home)
        except TreeFormatError:
            generated = None  # the mission's check says why it cannot be read
        if generated is not None:
            return generated
    ground = mission_ground(mission) if mission is not None else None
    if ground is not None:
        return ground_world(ground, home)
    if not default and home is None:
        return None
    world = default_world()
    if home is not None:
        world = dataclasses.replace(world, home=(home[0], home[1], home[2] if home[2] is not None else 0.0))
    return world


__all__ = ["MISSION_GROUNDS", "OPEN_REACH", "MissionGround", "ground_world", "mission_ground", "mission_places",
           "mission_world", "world_for"]
