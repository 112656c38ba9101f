"""Aerostack2's ``follow_path_gps`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class FollowPathGpsModule(ModuleBase):
    """follow_path_gps module."""

    __alias__ = "follow_path_gps"
    __deps__ = ["gps"]
