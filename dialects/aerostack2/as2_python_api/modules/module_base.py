"""Aerostack2's ``ModuleBase`` over aeroexec: a behavior module whose methods (``__call__``, ``go_to_point``...)
are read from :data:`aeroexec.dialects.aerostack2.behaviors.MODULES`, bound like Aerostack2 binds them and run
as the catalog requests they stand for."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from aeroexec.dialects import ros
from aeroexec.dialects.aerostack2 import behaviors as aerostack2
from aeroexec.dialects.aerostack2 import eras
from aeroexec.dialects.aerostack2.as2_python_api.behavior_actions.behavior_handler import BehaviorHandler
from aeroexec.dialects.aerostack2.behaviors import As2Error
from aeroexec.drones.interface import LandedState

if TYPE_CHECKING:
    from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase
    from aeroexec.dialects.aerostack2.as2_python_api.mission_interpreter.mission import MissionItem

logger = logging.getLogger(__name__)


def _method(name: str) -> Callable[..., bool]:
    def call(self: ModuleBase, *args: Any, **kwargs: Any) -> bool:
        return self._invoke(name, args, kwargs)

    call.__name__ = call.__qualname__ = name
    return call


class ModuleBase(BehaviorHandler):
    """A behavior module of a drone; subclasses name their ``__alias__`` and get its methods from the table."""

    __alias__ = ""
    __deps__: list[str] = []

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for name in aerostack2.MODULES.get(cls.__alias__, {}):
            if name != "__call__" and name not in cls.__dict__:
                setattr(cls, name, _method(name))

    def __init__(self, drone: DroneInterfaceBase, alias: str | None = None) -> None:
        super().__init__(drone)
        self.__alias__ = alias or type(self).__alias__
        drone.modules[self.__alias__] = self

    def __call__(self, *args: Any, **kwargs: Any) -> bool:
        return self._invoke("__call__", args, kwargs)

    def _invoke(self, name: str, args: tuple, kwargs: dict[str, Any]) -> bool:
        """Bind the call (a TypeError, as Python gives, for wrong arguments), then run its requests."""
        call = aerostack2.method(type(self).__alias__, name)
        try:
            bound = call.bind(args, kwargs)
        except As2Error as error:
            raise TypeError(error.message) from None
        drone = self._drone
        try:
            telemetry = drone.telemetry()
            requests = aerostack2.requests(call, bound, home=telemetry.home, yaw=telemetry.yaw,
                                           frames=drone.world_frames)
        except As2Error as error:
            drone.refuse(call.spelled, error.kind, error.message)
            return False
        if drone.takes_off_by_path and telemetry.landed_state is LandedState.ON_GROUND and telemetry.armed \
                and drone.info["offboard"]:
            by_path = eras.take_off_by_path(call.module, requests)
            if len(by_path) > len(requests):
                logger.warning("%s: %s", drone.drone_id, eras.RULE)
                requests = by_path
        return self._perform(requests)

    @classmethod
    def get_plan_item(cls, method_name: Callable | None = None, *args: Any, **kwargs: Any) -> MissionItem:
        """The mission interpreter's item for a call of ``method_name`` (``__call__`` by default)."""
        from aeroexec.dialects.aerostack2.as2_python_api.mission_interpreter.mission import MissionItem

        name = getattr(method_name, "__name__", method_name) or "__call__"
        call = aerostack2.method(cls.__alias__, name)
        return MissionItem(behavior=cls.__alias__, method=name, args=dict(zip(call.parameters, args, strict=False))
                           | kwargs)


def module_class(name: str) -> type[ModuleBase]:
    """The module class of ``takeoff``, ``rtl_module`` or ``as2_python_api.modules.rtl_module``."""
    import importlib

    alias = name.rsplit(".", 1)[-1].removesuffix("_module")
    alias = {"motion_reference_handler": "motion_ref_handler"}.get(alias, alias)
    if alias not in (*aerostack2.MODULES, "gps", "motion_ref_handler"):
        raise ModuleNotFoundError(f"Module {name} not found: aeroexec offers Aerostack2's own modules "
                                  f"({', '.join(aerostack2.MODULES)}, gps, motion_reference_handler); a module "
                                  f"of the mission's own talks to ROS 2 ({ros.ROS2_BEYOND})")
    file = {"motion_ref_handler": "motion_reference_handler", "goto": "go_to", "goto_gps": "go_to_gps"}.get(alias,
                                                                                                           alias)
    module = importlib.import_module(f"aeroexec.dialects.aerostack2.as2_python_api.modules.{file}_module")
    return next(v for v in vars(module).values() if isinstance(v, type) and issubclass(v, ModuleBase)
                and v.__alias__ == alias)


__all__ = ["ModuleBase", "module_class"]
