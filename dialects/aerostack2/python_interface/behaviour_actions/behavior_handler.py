"""Aerostack2 1.0's ``python_interface.behaviour_actions.behavior_handler``:
``as2_python_api.behavior_actions.behavior_handler``."""

from aeroexec.dialects.aerostack2.as2_python_api.behavior_actions.behavior_handler import BehaviorHandler

__all__ = ["BehaviorHandler"]
