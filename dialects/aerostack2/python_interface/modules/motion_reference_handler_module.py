"""Aerostack2 1.0's ``python_interface.modules.motion_reference_handler_module``:
``as2_python_api.modules.motion_reference_handler_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.motion_reference_handler_module import (
    MotionReferenceHandlerModule,
)

__all__ = ["MotionReferenceHandlerModule"]
