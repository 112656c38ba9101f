"""``python_interface.behaviour_actions.behavior_handler`` of Aerostack2 before 1.0 (the package was renamed
as2_python_api in December 2022): ``as2_python_api.behavior_actions.behavior_handler``."""

from aeroexec.dialects.aerostack2.as2_python_api.behavior_actions.behavior_handler import BehaviorHandler

__all__ = ["BehaviorHandler"]
