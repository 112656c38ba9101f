"""Aerostack2's ``DroneInterfaceGPS``: go_to and follow_path take GPS points, placed from the GPS origin (home)."""

from __future__ import annotations

from typing import Any

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase
from aeroexec.dialects.aerostack2.as2_python_api.modules.follow_path_gps_module import FollowPathGpsModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.go_to_gps_module import GoToGpsModule, GotoGpsModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.gps_module import GpsModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.land_module import LandModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.takeoff_module import TakeoffModule


class DroneInterfaceGPS(DroneInterfaceBase):
    """Drone interface node with GPS."""

    def __init__(self, drone_id: str = "drone0", verbose: bool = False, use_sim_time: bool = False,
                 spin_rate: float = 20.0, executor: Any = None) -> None:
        super().__init__(drone_id=drone_id, verbose=verbose, use_sim_time=use_sim_time, spin_rate=spin_rate)
        self.gps = GpsModule(drone=self)
        self.takeoff = TakeoffModule(drone=self)
        self.go_to = GoToGpsModule(drone=self)
        self.goto = GotoGpsModule(drone=self)  # the spelling of Aerostack2 before 1.0
        self.follow_path = FollowPathGpsModule(drone=self)
        self.land = LandModule(drone=self)
