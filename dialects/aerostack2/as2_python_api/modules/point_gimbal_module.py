"""Aerostack2's ``point_gimbal`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class PointGimbalModule(ModuleBase):
    """point_gimbal module."""

    __alias__ = "point_gimbal"
