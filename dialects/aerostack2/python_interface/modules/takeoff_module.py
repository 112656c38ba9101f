"""``python_interface.modules.takeoff_module`` of Aerostack2 before 1.0 (the package was renamed as2_python_api in
December 2022): ``as2_python_api.modules.takeoff_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.takeoff_module import TakeoffModule

__all__ = ["TakeoffModule"]
