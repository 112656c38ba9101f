"""Aerostack2's ``follow_path_gps`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.engine.missions.aerostack2.MODULES`."""

from aeroexec.aerostack.as2_python_api.modules.module_base import ModuleBase


class FollowPathGpsModule(ModuleBase):
    """follow_path_gps module."""

    __alias__ = "follow_path_gps"
    __deps__ = ["gps"]
