"""Aerostack2 1.0's ``python_interface.modules.takeoff_module``: ``as2_python_api.modules.takeoff_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.takeoff_module import TakeoffModule

__all__ = ["TakeoffModule"]
