"""Aerostack2's ``point_gimbal`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.engine.missions.aerostack2.MODULES`."""

from aeroexec.aerostack.as2_python_api.modules.module_base import ModuleBase


class PointGimbalModule(ModuleBase):
    """point_gimbal module."""

    __alias__ = "point_gimbal"
