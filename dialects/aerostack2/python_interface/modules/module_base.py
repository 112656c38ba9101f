"""``python_interface.modules.module_base`` of Aerostack2 before 1.0 (the package was renamed as2_python_api in December
2022): ``as2_python_api.modules.module_base``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import ModuleBase

__all__ = ["ModuleBase"]
