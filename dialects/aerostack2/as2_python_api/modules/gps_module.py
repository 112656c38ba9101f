"""Aerostack2's ``gps`` module: the GPS origin of the drone's earth frame (its home point here) and its fix."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase
from aeroexec.engine.errors import WRONG_VALUE

if TYPE_CHECKING:
    from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase

#: How far (meters) an origin may be from the home point and still be it.
ORIGIN_TOLERANCE = 1.0


class GpsModule(ModuleBase):
    """gps module: ``origin`` [lat, lon, alt], ``pose`` (the fix now), ``set_origin``."""

    __alias__ = "gps"

    def __init__(self, drone: DroneInterfaceBase) -> None:
        super().__init__(drone, self.__alias__)

    def __call__(self) -> None:
        return None

    @property
    def origin(self) -> list[float] | None:
        """The GPS origin of the earth frame: the drone's home point (None while the drone has none)."""
        home = self._drone.telemetry().home
        return None if home is None else list(home)

    @property
    def pose(self) -> list[float] | None:
        """The drone's GPS fix [lat, lon, alt] now."""
        from aeroexec.drones.geodesy import enu_to_geodetic

        telemetry = self._drone.telemetry()
        return None if telemetry.home is None else list(enu_to_geodetic(telemetry.position, telemetry.home))

    def set_origin(self, gps_pose: list[float]) -> bool:
        """True when ``gps_pose`` is the home point (aeroexec's earth frame is fixed at home, so an origin
        elsewhere is refused and the mission is told so)."""
        from aeroexec.drones.geodesy import geodetic_to_enu

        home = self._drone.telemetry().home
        if home is None or len(gps_pose) < 2:
            return False
        east, north, _ = geodetic_to_enu((gps_pose[0], gps_pose[1], home[2]), home)
        if math.hypot(east, north) <= ORIGIN_TOLERANCE:
            return True
        self._drone.refuse("gps.set_origin", WRONG_VALUE,
                           f"The origin ({gps_pose[0]}, {gps_pose[1]}) is {math.hypot(east, north):.0f} m from the "
                           f"home point ({home[0]}, {home[1]}): the earth frame is fixed at home (fly with --home "
                           f"at this origin, or a world whose home it is)")
        return False
