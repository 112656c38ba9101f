"""A vehicle profile: the figures of the vehicle a user flies (``aeroexec run --vehicle FILE``, ``aeroexec verify
--vehicle FILE``), read from YAML with ``file:line`` in every error.

Without a profile every estimate is the simulated multicopter's (:class:`aeroexec.drones.sim.SimConfig`: 20 minutes
of hover on a full battery, PX4's default speeds and rates). A profile replaces the figures it gives, in one place:
the :class:`SimConfig` it makes (:meth:`VehicleProfile.config`) is what the simulator flies, what verify's route
(``trees/route.py``) costs each leg with, and what the safety rules' vehicle model (:class:`VehicleModel`) reads;
its ceiling is the highest a route may climb. Keys (all optional; minutes, meters, m/s)::

    name: survey hexacopter
    endurance: 55          # minutes of hover on a full battery (the simulator's battery_hover_minutes)
    cruise_speed: 8        # m/s: a go-to's speed when none is asked
    max_speed: 15          # m/s horizontally
    climb_rate: 2          # m/s: the take-off's climb
    max_climb_rate: 4      # m/s: other climbs
    descent_rate: 2        # m/s
    land_speed: 0.7        # m/s: the last meters of a landing
    ceiling: 120           # m above home: no route climbs higher
    return_altitude: 30    # m: a return home climbs to it first
    failsafe_battery: 10   # %: at or below it the vehicle lands (no arming)
    camera: false          # it has no camera: photo items are a warning before flight, and skipped in flight
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from aeroexec.drones.sim.config import SimConfig
from aeroexec.drones.sim.world import WorldError
from aeroexec.drones.sim.world_file import _Reader

from aeroexec.limits import InputError, compose_yaml, read_text

#: A profile's keys: (the SimConfig field each sets, what it is, the most it may be).
FIGURES: dict[str, tuple[str, str, float]] = {
    "endurance": ("battery_hover_minutes", "minutes of hover on a full battery", 24 * 60.0),
    "cruise_speed": ("cruise_speed", "m/s", 100.0),
    "max_speed": ("max_speed", "m/s", 100.0),
    "climb_rate": ("climb_rate", "m/s", 50.0),
    "max_climb_rate": ("max_climb_rate", "m/s", 50.0),
    "descent_rate": ("descent_rate", "m/s", 50.0),
    "land_speed": ("land_speed", "m/s", 10.0),
    "return_altitude": ("return_altitude", "m", 10000.0),
    "failsafe_battery": ("failsafe_battery_percent", "%", 99.0),
}
KEYS = {"name", "ceiling", "camera", *FIGURES}


class VehicleProfileError(ValueError):
    """A vehicle profile that cannot be read: the message names the file and line."""


@dataclass(frozen=True)
class VehicleProfile:
    """The figures a profile gives (SimConfig field -> value), its ceiling (m above home) and where it was read."""

    figures: dict[str, float] = field(default_factory=dict)
    ceiling: float | None = None
    camera: bool = True
    name: str = ""
    source: str = ""

    def config(self, base: SimConfig | None = None) -> SimConfig:
        """``base`` (default: the simulated multicopter's) with this profile's figures."""
        return replace(base or SimConfig(), **self.figures, ceiling=self.ceiling, camera=self.camera)

    def described(self) -> str:
        """A short line: ``vehicle survey hexacopter (vehicle.yaml): 55 min of hover, ceiling 120 m``."""
        config = self.config()
        parts = [f"{config.battery_hover_minutes:g} min of hover", f"cruise {config.cruise_speed:g} m/s"]
        if self.ceiling is not None:
            parts.append(f"ceiling {self.ceiling:g} m")
        return f"vehicle {self.name or Path(self.source).stem} ({self.source}): {', '.join(parts)}"


def parse_vehicle_profile(text: str, source: str = "<vehicle>") -> VehicleProfile:
    """The profile in YAML ``text``; ``source`` names the file in errors (:class:`VehicleProfileError`)."""
    try:
        root = compose_yaml(text, source)
    except InputError as exc:
        raise VehicleProfileError(str(exc)) from None
    if root is None:
        raise VehicleProfileError(f"{source}:1: the vehicle profile is empty: give its figures (endurance, "
                                  f"speeds, ceiling...)")
    from yaml.nodes import MappingNode  # here: PyYAML is imported by compose_yaml when a profile is read

    reader = _Reader(source)
    try:
        if not isinstance(root, MappingNode):
            raise reader.error(root, "a vehicle profile is a mapping of its figures (endurance: 55, ...)")
        keys = reader.mapping(root, "the vehicle profile", set(), KEYS)
        figures = {FIGURES[key][0]: reader.number(node, f"{key} ({FIGURES[key][1]})", positive=True,
                                                  maximum=FIGURES[key][2])
                   for key, node in keys.items() if key in FIGURES}
        ceiling = reader.number(keys["ceiling"], "ceiling (m above home)", positive=True) \
            if "ceiling" in keys else None
        name = reader.string(keys["name"], "name") if "name" in keys else ""
        camera = reader.boolean(keys["camera"], "camera") if "camera" in keys else True
        profile = VehicleProfile(figures, ceiling, camera, name, source)
        try:
            config = profile.config()
        except ValueError as exc:
            raise reader.error(root, f"these figures do not make a vehicle: {exc}") from None
        if config.cruise_speed > config.max_speed:
            node = keys.get("cruise_speed") or keys.get("max_speed")
            raise reader.error(node, f"cruise_speed {config.cruise_speed:g} m/s is above max_speed "
                                     f"{config.max_speed:g} m/s")
        if ceiling is not None and "return_altitude" in keys and config.return_altitude > ceiling:
            raise reader.error(keys["return_altitude"], f"return_altitude {config.return_altitude:g} m is above the "
                                                        f"ceiling {ceiling:g} m")
    except WorldError as exc:
        raise VehicleProfileError(str(exc)) from None
    if not math.isfinite(config.battery_hover_minutes):
        raise VehicleProfileError(f"{source}: endurance must be finite")
    return profile


def load_vehicle_profile(path: str | Path) -> VehicleProfile:
    """Read a vehicle profile; raises :class:`VehicleProfileError` naming ``file:line`` on any mistake."""
    try:
        text = read_text(path, what="the vehicle profile")
    except InputError as exc:
        raise VehicleProfileError(str(exc)) from None
    return parse_vehicle_profile(text, str(path))


__all__ = ["VehicleProfile", "VehicleProfileError", "load_vehicle_profile", "parse_vehicle_profile"]
