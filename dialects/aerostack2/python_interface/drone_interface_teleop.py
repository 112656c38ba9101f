"""``python_interface.drone_interface_teleop``, the Python API of Aerostack2 before 1.0 (the package was renamed
as2_python_api in December 2022): ``as2_python_api.drone_interface_teleop``'s DroneInterfaceTeleop, flown by that
era's rule for a follow_path from the ground (:mod:`aeroexec.dialects.aerostack2.eras`)."""

from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_teleop import (
    DroneInterfaceTeleop as _DroneInterfaceTeleop,
)


class DroneInterfaceTeleop(_DroneInterfaceTeleop):
    """DroneInterfaceTeleop of python_interface: a follow_path from the ground takes off by its path, as it did then."""

    takes_off_by_path = True


__all__ = ["DroneInterfaceTeleop"]
