"""Aerostack2 1.0's ``python_interface.modules.goto_gps_module``: ``as2_python_api.modules.go_to_gps_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.go_to_gps_module import GotoGpsModule

__all__ = ["GotoGpsModule"]
