"""Aerostack2 1.0's ``python_interface.modules.goto_module``: ``as2_python_api.modules.go_to_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.go_to_module import GotoModule

__all__ = ["GotoModule"]
