"""Aerostack2 1.0's ``python_interface.drone_interface``: ``as2_python_api.drone_interface``."""

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface import DroneInterface

__all__ = ["DroneInterface"]
