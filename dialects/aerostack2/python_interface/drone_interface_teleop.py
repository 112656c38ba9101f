"""Aerostack2 1.0's ``python_interface.drone_interface_teleop``: ``as2_python_api.drone_interface_teleop``."""

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_teleop import DroneInterfaceTeleop

__all__ = ["DroneInterfaceTeleop"]
