"""Aerostack2 1.0's ``python_interface.modules.gps_module``: ``as2_python_api.modules.gps_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.gps_module import GpsModule

__all__ = ["GpsModule"]
