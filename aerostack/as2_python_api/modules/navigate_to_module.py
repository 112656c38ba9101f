"""Aerostack2's ``navigate_to`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.engine.missions.aerostack2.MODULES`."""

from aeroexec.aerostack.as2_python_api.modules.module_base import ModuleBase


class NavigateToModule(ModuleBase):
    """navigate_to module."""

    __alias__ = "navigate_to"
