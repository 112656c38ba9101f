"""Aerostack2 1.0's ``python_interface.modules.follow_path_gps_module``:
``as2_python_api.modules.follow_path_gps_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.follow_path_gps_module import FollowPathGpsModule

__all__ = ["FollowPathGpsModule"]
