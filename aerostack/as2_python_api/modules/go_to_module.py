"""Aerostack2's ``go_to`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.engine.missions.aerostack2.MODULES`."""

from as2_python_api.modules.module_base import ModuleBase


class GoToModule(ModuleBase):
    """go_to module."""

    __alias__ = "go_to"
