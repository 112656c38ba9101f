"""The behavior handlers of Aerostack2 before 1.0 (the package was renamed as2_python_api in December 2022)
(``python_interface.behaviour_actions``)."""
