"""Aerostack2's ``go_to`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class GoToModule(ModuleBase):
    """go_to module."""

    __alias__ = "go_to"


class GotoModule(ModuleBase):
    """The goto module of Aerostack2 before 1.0 (``drone.goto``), as go_to with x, y, z written _x, _y, _z."""

    __alias__ = "goto"
