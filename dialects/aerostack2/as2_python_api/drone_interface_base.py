"""Aerostack2's ``DroneInterfaceBase`` over aeroexec: one drone, bound by its namespace to the engine that flies it.

What Aerostack2's drone interface offers besides its behavior modules: ``arm()``, ``offboard()``, ``disarm()``,
``manual()`` (idempotent: True when the drone is, or now is, in that state), ``position``, ``orientation``,
``speed``, ``info``, ``load_module()``, ``shutdown()``; and a publisher of messages used as data
(``create_publisher(ColorRGBA, "/drone0/leds/control", 10)``: each message published is in the event log, as
``published``, and nothing else hears it, as in a ROS 2 graph where nothing subscribes to that topic). The rest of a
ROS 2 node (subscriptions, services, parameters, timers) is refused: this mission uses ROS 2 beyond the drone
interface.
"""

from __future__ import annotations

import logging
import math
from typing import Any

from aeroexec.dialects import ros
from aeroexec.dialects.aerostack2.as2_msgs.msg import PlatformStatus
from aeroexec.dialects.aerostack2.node_api import NODE_API
from aeroexec.dialects.aerostack2.rclpy.publisher import Publisher, publisher, resolve_topic
from aeroexec.drones.interface import LandedState, Telemetry
from aeroexec.engine import api
from aeroexec.engine.missions import script

#: Engine seconds a drone command (arm, disarm) may take before it counts as refused.
COMMAND_TIMEOUT = 5.0
_STATES = {LandedState.TAKING_OFF: PlatformStatus.TAKING_OFF, LandedState.IN_AIR: PlatformStatus.FLYING,
           LandedState.LANDING: PlatformStatus.LANDING}


class _Logger:
    """What ``get_logger()`` gives: rclpy's logger calls, into Python's logging."""

    def __init__(self, name: str) -> None:
        self._logger = logging.getLogger(f"as2.{name}")

    def debug(self, message: Any, *args: Any, **kwargs: Any) -> None:
        self._logger.debug("%s", message)

    def info(self, message: Any, *args: Any, **kwargs: Any) -> None:
        self._logger.info("%s", message)

    def warning(self, message: Any, *args: Any, **kwargs: Any) -> None:
        self._logger.warning("%s", message)

    warn = warning

    def error(self, message: Any, *args: Any, **kwargs: Any) -> None:
        self._logger.error("%s", message)

    fatal = error

    def set_level(self, level: Any) -> None:
        return None


class DroneInterfaceBase:
    """Drone interface base node: the drone ``drone_id`` (its namespace)."""

    #: A follow_path from the ground takes off by its path, as before December 2022 (python_interface's
    #: interfaces: :mod:`aeroexec.dialects.aerostack2.eras`); as2_python_api's refuse it, as Aerostack2 does now.
    takes_off_by_path = False

    def __init__(self, drone_id: str = "drone0", verbose: bool = False, use_sim_time: bool = False,
                 spin_rate: float = 20.0, executor: Any = None) -> None:
        self.modules: dict[str, Any] = {}
        self.namespace = drone_id
        self.engine = script.drone_engine(drone_id)
        self._logger = _Logger(drone_id)
        self._offboard = False
        self._logger.info(f"{drone_id} interface initialized")

    # -- ROS 2's node, which this is not ----------------------------------------------------------------
    def __getattr__(self, name: str) -> Any:
        if name.startswith(NODE_API) or name in ("context", "executor", "handle"):
            return ros.Refused(f"{type(self).__name__}.{name}")
        raise AttributeError(f"'{type(self).__name__}' object has no attribute '{name}'")

    def get_logger(self) -> _Logger:
        return self._logger

    def create_publisher(self, msg_type: Any, topic: str, qos_profile: Any = 10, **kwargs: Any) -> Publisher:
        """A publisher of ``msg_type`` (a message type used as data: ``std_msgs.msg.ColorRGBA``...) on ``topic``
        (rclpy's stand-in's: its messages go to this drone's event log); another type (an image, a type of a package
        aeroexec does not serve) is refused by name."""
        return publisher(type(self).__name__, msg_type, resolve_topic(str(topic), self.namespace),
                         lambda: self.engine)

    def destroy_publisher(self, publisher: Publisher) -> bool:
        return publisher.destroy()

    # -- the drone ------------------------------------------------------------------------------------------
    @property
    def drone_id(self) -> str:
        return self.namespace

    @property
    def earth_frame_id(self) -> str:
        return "earth"

    @property
    def base_frame_id(self) -> str:
        return f"{self.namespace}/base_link"

    @property
    def world_frames(self) -> tuple[Any, ...]:
        """The named frames of the world the drone flies in (a simulator world's models: ``gate_0/link``)."""
        return tuple(getattr(getattr(self.engine.drone, "world", None), "frames", ()) or ())

    def telemetry(self) -> Telemetry:
        """The drone's state now (a call to the engine: a loop reading it sees time move)."""
        engine = self.engine
        return engine.bridge.call(engine.drone.telemetry)

    @property
    def info(self) -> dict[str, Any]:
        """``connected``, ``armed``, ``offboard``, ``state`` (PlatformStatus), ``yaw_mode``, ``control_mode``."""
        t = self.telemetry()
        state = _STATES.get(t.landed_state, PlatformStatus.LANDED if t.armed else PlatformStatus.DISARMED)
        return {"connected": t.link_ok, "armed": t.armed, "offboard": self._offboard and t.armed, "state": state,
                "yaw_mode": 0, "control_mode": 0}

    @property
    def position(self) -> list[float]:
        """[x, y, z] in meters, earth frame (local ENU from home)."""
        return list(self.telemetry().position)

    @property
    def orientation(self) -> list[float]:
        """[roll, pitch, yaw] in radians (the engine knows the yaw; roll and pitch are 0)."""
        return [0.0, 0.0, math.radians(self.telemetry().yaw)]

    @property
    def speed(self) -> list[float]:
        """[vx, vy, vz] in m/s, earth frame."""
        return list(self.telemetry().velocity)

    def _command(self, name: str) -> bool:
        """Arm or disarm through the engine; True when the drone did it within COMMAND_TIMEOUT."""
        engine = self.engine
        with api.talking_to(engine):
            handle = engine.bridge.call(getattr(engine.drone, name))
            waited = 0.0
            while not handle.done and waited < COMMAND_TIMEOUT:
                api.wait(0.1)
                waited += 0.1
            ok = handle.done and handle.ok
            where = api.caller_location()
            engine.bridge.call(lambda: engine.log.record(
                "drone_command", name.upper(), "done" if ok else handle.reason or "no answer", source="mission",
                where=where))
        if not ok:
            self._logger.warning(f"{name} refused: {handle.reason or 'no answer'}")
        return ok

    def arm(self) -> bool:
        """Arm the drone (True at once when it is armed already; TAKE_OFF arms it too)."""
        return True if self.telemetry().armed else self._command("arm")

    def disarm(self) -> bool:
        """Disarm the drone: True when it is disarmed; refused (False) while it flies."""
        return True if not self.telemetry().armed else self._command("disarm")

    def offboard(self) -> bool:
        """Let the mission command the drone (aeroexec's behaviors choose the flight mode): True."""
        self._offboard = True
        return True

    def manual(self) -> bool:
        """Give the drone back to its pilot: True (the run lands a drone left in the air)."""
        self._offboard = False
        return True

    def refuse(self, what: str, kind: str, message: str) -> None:
        """Record a call the engine cannot serve as a refused request: the event log says it (once, with a count
        when it repeats) and the run ends completed with refused requests."""
        engine = self.engine
        where = api.caller_location()
        engine.bridge.call(lambda: engine.log.record("rejected", what, message, error=kind, source="mission",
                                                     where=where))
        self._logger.debug(f"{what}: {message}")

    def load_module(self, pkg: str) -> None:
        """Load a behavior module (``rtl_module``, ``as2_python_api.modules.rtl_module``...), its dependencies first."""
        from aeroexec.dialects.aerostack2.as2_python_api.modules.module_base import module_class

        cls = module_class(pkg)
        if cls.__alias__ in self.modules:
            return
        for dependency in cls.__deps__:
            self.load_module(dependency)
        setattr(self, cls.__alias__, cls(self))

    def send_emergency_land(self) -> None:
        """Land now (LAND)."""
        from aeroexec.dialects.aerostack2.as2_python_api.modules.land_module import LandModule

        LandModule(self, "emergency_land")()

    def send_emergency_hover(self) -> None:
        """Hold position now (KEEP_HOVERING)."""
        from aeroexec.dialects.aerostack2.as2_python_api.modules.motion_reference_handler_module import (
            MotionReferenceHandlerModule,
        )

        MotionReferenceHandlerModule(self).hover()

    def shutdown(self) -> None:
        """Leave the drone interface (again: nothing happens); the drone goes on as it is, as in Aerostack2."""
        self._logger.info(f"{self.namespace} interface shut down")
