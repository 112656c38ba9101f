"""The behavior modules of Aerostack2 before 1.0 (the package was renamed as2_python_api in December 2022)
(``python_interface.modules``): Aerostack2's own, under that version's file names (``goto_module``,
``goto_gps_module``)."""
