"""``python_interface.modules.motion_reference_handler_module`` of Aerostack2 before 1.0 (the package was renamed
as2_python_api in December 2022): ``as2_python_api.modules.motion_reference_handler_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.motion_reference_handler_module import (
    MotionReferenceHandlerModule,
)

__all__ = ["MotionReferenceHandlerModule"]
