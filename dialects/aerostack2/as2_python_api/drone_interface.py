"""Aerostack2's ``DroneInterface``: the drone interface with the takeoff, go_to, follow_path and land modules."""

from __future__ import annotations

from typing import Any

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase
from aeroexec.dialects.aerostack2.as2_python_api.modules.follow_path_module import FollowPathModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.go_to_module import GoToModule, GotoModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.land_module import LandModule
from aeroexec.dialects.aerostack2.as2_python_api.modules.takeoff_module import TakeoffModule


class DroneInterface(DroneInterfaceBase):
    """Drone interface node."""

    def __init__(self, drone_id: str = "drone0", verbose: bool = False, use_sim_time: bool = False,
                 spin_rate: float = 20.0, executor: Any = None) -> None:
        super().__init__(drone_id=drone_id, verbose=verbose, use_sim_time=use_sim_time, spin_rate=spin_rate)
        self.takeoff = TakeoffModule(drone=self)
        self.go_to = GoToModule(drone=self)
        self.goto = GotoModule(drone=self)  # the spelling of Aerostack2 before 1.0
        self.follow_path = FollowPathModule(drone=self)
        self.land = LandModule(drone=self)


__all__ = ["DroneInterface", "DroneInterfaceBase"]
