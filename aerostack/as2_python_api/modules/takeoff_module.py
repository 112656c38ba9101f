"""Aerostack2's ``takeoff`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.engine.missions.aerostack2.MODULES`."""

from aeroexec.aerostack.as2_python_api.modules.module_base import ModuleBase


class TakeoffModule(ModuleBase):
    """takeoff module."""

    __alias__ = "takeoff"
