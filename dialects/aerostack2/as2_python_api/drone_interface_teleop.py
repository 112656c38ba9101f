"""Aerostack2's ``DroneInterfaceTeleop``: the drone interface with motion references (``motion_ref_handler``)."""

from __future__ import annotations

from typing import Any

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface import DroneInterface
from aeroexec.dialects.aerostack2.as2_python_api.modules.motion_reference_handler_module import (
    MotionReferenceHandlerModule,
)


class DroneInterfaceTeleop(DroneInterface):
    """Drone interface node with motion references."""

    def __init__(self, drone_id: str = "drone0", verbose: bool = False, use_sim_time: bool = False,
                 spin_rate: float = 20.0, executor: Any = None) -> None:
        super().__init__(drone_id=drone_id, verbose=verbose, use_sim_time=use_sim_time, spin_rate=spin_rate)
        self.motion_ref_handler = MotionReferenceHandlerModule(drone=self)
