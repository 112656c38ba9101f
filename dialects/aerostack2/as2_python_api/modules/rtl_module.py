"""Aerostack2's ``rtl`` module: its methods and the catalog requests they stand for are in
:data:`aeroexec.dialects.aerostack2.behaviors.MODULES`."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase


class RTLModule(ModuleBase):
    """rtl module."""

    __alias__ = "rtl"
    __deps__ = ["go_to", "land"]
