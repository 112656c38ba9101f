"""Aerostack2's behavior modules (``takeoff``, ``go_to``, ``follow_path``, ``land``...), one per file as in
Aerostack2, each a :class:`~as2_python_api.modules.module_base.ModuleBase` over the table of
:mod:`aeroexec.dialects.aerostack2.behaviors`."""
