"""Aerostack2's ``takeoff`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class TakeoffModule(ModuleBase):
    """takeoff module."""

    __alias__ = "takeoff"
