"""The simulation world an Aerostack2 project launches Gazebo from: its world config (``as2_gazebo_assets``'
``simulation_config_file``: ``sim_config/world.json``, ``config_sim/world.yaml``...), found where the project keeps
it, relative to the script as the project's launch files name it.

A config names the world, its ``drones`` (``model_name``, spawn ``xyz``) and its ``objects`` (``model_type``,
``model_name``, ``xyz``, ``rpy``). A script's flight places them as Gazebo does: the drone starts where the config
spawns it (a swarm's drones where it spawns each), and each object's frame (``NAME/link``, the model's frame, as
the projects' tf publishers name it) is a :class:`~aeroexec.drones.sim.world.Frame` of the world at the object's
pose, ENU meters from the (first) drone's start, so a behavior given a point in that frame flies there. The
objects' solids (meshes) are not simulated.

Of the configs a project keeps, the one whose drones are the script's (every drone the script names, fewest
others; then the shortest name: ``world.json`` before ``world_swarm.json``) is the one its launch file would
pick for it.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from aeroexec.drones.sim.world import Frame

from aeroexec.limits import MAX_FILE_BYTES, load_yaml

logger = logging.getLogger(__name__)

#: Where Aerostack2's projects keep their simulation config, relative to the project's folder.
CONFIG_FOLDERS = ("sim_config", "config_sim", "config", "config_sim/config")
#: How its file is named (``world_swarm.json``, ``world_2drones.yaml``... start so).
CONFIG_PREFIX = "world"
CONFIG_SUFFIXES = (".json", ".yaml", ".yml")


@dataclass(frozen=True)
class SimWorld:
    """A project's world config, read: its ``file``, the drones' spawn points by name and its objects' frames
    (their poses in Gazebo's world frame)."""

    file: Path
    drones: dict[str, tuple[float, float, float]]
    frames: tuple[Frame, ...]

    def _start(self, drone: str | None) -> tuple[float, float, float]:
        return self.drones.get(drone or "", next(iter(self.drones.values()), (0.0, 0.0, 0.0)))

    def starts_from(self, drone: str | None) -> tuple[tuple[str, tuple[float, float]], ...]:
        """Where each of its drones starts, in ENU meters from where ``drone`` starts."""
        start = self._start(drone)
        return tuple((name, (round(x - start[0], 6), round(y - start[1], 6)))
                     for name, (x, y, _) in self.drones.items())

    def frames_from(self, drone: str | None) -> tuple[Frame, ...]:
        """The objects' frames in ENU meters from where ``drone`` starts (its first drone's start when not named
        or not among its drones)."""
        start = self._start(drone)
        return tuple(Frame(f.name, (round(f.position[0] - start[0], 6), round(f.position[1] - start[1], 6),
                                    f.position[2]), f.rpy) for f in self.frames)


def _triple(value: Any) -> tuple[float, float, float] | None:
    if isinstance(value, list | tuple) and len(value) == 3 and all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        return float(value[0]), float(value[1]), float(value[2])
    return None


def read_config(file: Path) -> SimWorld | None:
    """The world config ``file``; None when it is not one (not JSON/YAML of that shape)."""
    try:
        if file.stat().st_size > MAX_FILE_BYTES:
            return None
        text = file.read_text(encoding="utf-8")
        data = json.loads(text) if file.suffix == ".json" else load_yaml(text, str(file))
    except Exception as exc:  # unreadable, not JSON or YAML: not a config, skipped, and said (it may be a broken one)
        logger.warning("%s is not read as the project's simulation world: %s", file, exc)
        return None
    if not isinstance(data, dict) or not isinstance(data.get("drones", []), list) or not isinstance(
            data.get("objects", []), list) or not ("drones" in data or "objects" in data):
        return None
    drones: dict[str, tuple[float, float, float]] = {}
    for drone in data.get("drones") or ():
        xyz = _triple(drone.get("xyz")) if isinstance(drone, dict) else None
        if xyz is not None and isinstance(drone.get("model_name"), str):
            drones[drone["model_name"]] = xyz
    frames = []
    for number, item in enumerate(data.get("objects") or (), 1):
        if not isinstance(item, dict) or not isinstance(item.get("model_name"), str):
            logger.warning("%s: object %d has no model_name: it is not a frame of the world", file, number)
            continue
        xyz, rpy = _triple(item.get("xyz")), _triple(item.get("rpy", [0, 0, 0]))
        if xyz is not None and rpy is not None:
            frames.append(Frame(f"{item['model_name']}/link", xyz, rpy))
        else:
            logger.warning("%s: object %d (%s) needs xyz and rpy of three numbers each: it is not a frame of the "
                           "world", file, number, item["model_name"])
    return SimWorld(file, drones, tuple(frames))


def _candidates(script: Path) -> list[Path]:
    found = []
    for project in dict.fromkeys((script.parent, script.parent.parent)):  # the script's folder, or its parent's
        for folder in CONFIG_FOLDERS:
            place = project / folder
            if place.is_dir():
                found += sorted(p for p in place.iterdir() if p.name.startswith(CONFIG_PREFIX)
                                and p.suffix in CONFIG_SUFFIXES and p.is_file())
        if found:
            return found  # the nearest project's
    return found


def project_world(script: Path, drones: Sequence[str]) -> SimWorld | None:
    """The world config of the project ``script`` belongs to that its launch file would pick for the script's
    ``drones`` (see the module's docstring); None when the project keeps none."""
    configs = [c for c in (read_config(p) for p in _candidates(script)) if c is not None]
    wanted = set(drones)
    fitting = [c for c in configs if wanted <= set(c.drones)] or ([c for c in configs if not c.drones]
                                                                  if wanted else configs)
    if not fitting:
        return None
    return min(fitting, key=lambda c: (len(set(c.drones) - wanted), len(c.file.name), c.file.name))


__all__ = ["CONFIG_FOLDERS", "SimWorld", "project_world", "read_config"]
