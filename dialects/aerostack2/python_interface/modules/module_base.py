"""Aerostack2 1.0's ``python_interface.modules.module_base``: ``as2_python_api.modules.module_base``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase

__all__ = ["ModuleBase"]
