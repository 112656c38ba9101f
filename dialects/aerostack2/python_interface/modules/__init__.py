"""Aerostack2 1.0's behavior modules (``python_interface.modules``): Aerostack2's own, under that version's file
names (``goto_module``, ``goto_gps_module``)."""
