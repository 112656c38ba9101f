"""Aerostack2 1.0's ``python_interface.drone_interface_gps``: ``as2_python_api.drone_interface_gps``."""

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_gps import DroneInterfaceGPS

__all__ = ["DroneInterfaceGPS"]
