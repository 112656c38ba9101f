"""Aerostack2 1.0's ``python_interface.modules.land_module``: ``as2_python_api.modules.land_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.land_module import LandModule

__all__ = ["LandModule"]
