"""Aerostack2's ``follow_path`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class FollowPathModule(ModuleBase):
    """follow_path module."""

    __alias__ = "follow_path"
