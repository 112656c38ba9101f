"""``python_interface.modules.gps_module`` of Aerostack2 before 1.0 (the package was renamed as2_python_api in December
2022): ``as2_python_api.modules.gps_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.gps_module import GpsModule

__all__ = ["GpsModule"]
