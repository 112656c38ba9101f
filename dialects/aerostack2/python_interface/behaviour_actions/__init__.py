"""Aerostack2 1.0's behavior handlers (``python_interface.behaviour_actions``)."""
