"""Aerostack2's ``go_to_gps`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class GoToGpsModule(ModuleBase):
    """go_to_gps module."""

    __alias__ = "go_to_gps"
    __deps__ = ["gps"]


class GotoGpsModule(ModuleBase):
    """The goto module of GPS drone interfaces of Aerostack2 before 1.0 (``drone.goto``)."""

    __alias__ = "goto_gps"
    __deps__ = ["gps"]
