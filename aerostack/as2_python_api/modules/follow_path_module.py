"""Aerostack2's ``follow_path`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.engine.missions.aerostack2.MODULES`."""

from aeroexec.aerostack.as2_python_api.modules.module_base import ModuleBase


class FollowPathModule(ModuleBase):
    """follow_path module."""

    __alias__ = "follow_path"
