"""``python_interface.modules.follow_path_gps_module`` of Aerostack2 before 1.0 (the package was renamed as2_python_api
in December 2022): ``as2_python_api.modules.follow_path_gps_module``."""

from aeroexec.dialects.aerostack2.as2_python_api.modules.follow_path_gps_module import FollowPathGpsModule

__all__ = ["FollowPathGpsModule"]
