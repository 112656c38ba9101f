"""Aerostack2 1.0's ``python_interface.drone_interface_base``: ``as2_python_api.drone_interface_base``."""

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase

__all__ = ["DroneInterfaceBase"]
