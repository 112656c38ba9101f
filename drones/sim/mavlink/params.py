"""The MAVLink parameter protocol of the simulated vehicle: a small table of PX4 parameters.

Answers PARAM_REQUEST_LIST, PARAM_REQUEST_READ and PARAM_SET with PARAM_VALUE. Integer parameters are
encoded bytewise in the float field, as PX4 does (MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE).
"""

from __future__ import annotations

import logging
import math
import struct
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from pymavlink.dialects.v20 import common as mavlink

logger = logging.getLogger(__name__)


@dataclass(slots=True)
class Parameter:
    """One parameter: its PX4 name, value, type and the range a PARAM_SET must respect."""

    name: str
    value: float
    is_int: bool = False
    minimum: float = -math.inf
    maximum: float = math.inf
    description: str = ""


def encode_value(param: Parameter) -> tuple[float, int]:
    """The float to put in PARAM_VALUE and its MAV_PARAM_TYPE."""
    if param.is_int:
        return struct.unpack("<f", struct.pack("<i", int(param.value)))[0], mavlink.MAV_PARAM_TYPE_INT32
    return float(param.value), mavlink.MAV_PARAM_TYPE_REAL32


def decode_value(value: float, param_type: int) -> float:
    """The number a PARAM_SET carries, undoing the bytewise encoding of integer types."""
    if param_type in (mavlink.MAV_PARAM_TYPE_INT32, mavlink.MAV_PARAM_TYPE_UINT32):
        return float(struct.unpack("<i", struct.pack("<f", value))[0])
    if param_type in (mavlink.MAV_PARAM_TYPE_INT8, mavlink.MAV_PARAM_TYPE_UINT8):
        return float(struct.pack("<f", value)[0])
    if param_type in (mavlink.MAV_PARAM_TYPE_INT16, mavlink.MAV_PARAM_TYPE_UINT16):
        return float(struct.unpack("<h", struct.pack("<f", value)[:2])[0])
    return float(value)


class ParameterServer:
    """Serves a parameter table over one MAVLink encoder; ``on_change`` hears every accepted PARAM_SET."""

    def __init__(
        self,
        mav: mavlink.MAVLink,
        params: Iterable[Parameter],
        on_change: Callable[[str, float], None] | None = None,
        statustext: Callable[[int, str], None] | None = None,
    ) -> None:
        self._mav = mav
        self._params = {p.name: p for p in sorted(params, key=lambda p: p.name)}
        self._names = list(self._params)
        self._on_change = on_change
        self._statustext = statustext

    def get(self, name: str) -> float:
        return self._params[name].value

    def set(self, name: str, value: float) -> None:
        """Set a value locally (no message), e.g. from the simulation's configuration."""
        self._params[name].value = value

    def names(self) -> list[str]:
        return list(self._names)

    def handle(self, msg) -> bool:
        """Answer a parameter message; False when ``msg`` is not one."""
        kind = msg.get_type()
        if kind == "PARAM_REQUEST_LIST":
            for name in self._names:
                self._send(name)
            return True
        if kind == "PARAM_REQUEST_READ":
            name = self._lookup(msg.param_id, msg.param_index)
            if name is not None:
                self._send(name)
            else:
                logger.debug("parameter read of unknown %r (index %d) ignored", msg.param_id, msg.param_index)
            return True
        if kind == "PARAM_SET":
            self._set(msg)
            return True
        return False

    def _lookup(self, param_id: str, index: int) -> str | None:
        if index >= 0:
            return self._names[index] if index < len(self._names) else None
        name = _clean(param_id)
        return name if name in self._params else None

    def _set(self, msg) -> None:
        name = _clean(msg.param_id)
        param = self._params.get(name)
        if param is None:
            self._tell(mavlink.MAV_SEVERITY_WARNING, f"Parameter {name} not found")
            return
        value = decode_value(msg.param_value, msg.param_type)
        if param.is_int:
            value = float(round(value))
        if not math.isfinite(value) or not param.minimum <= value <= param.maximum:
            # PX4 would refuse the value: answer with the unchanged one so the sender sees it failed.
            self._tell(
                mavlink.MAV_SEVERITY_WARNING, f"{name}: {value:g} out of range [{param.minimum:g}, {param.maximum:g}]"
            )
            self._send(name)
            return
        param.value = value
        self._send(name)
        if self._on_change is not None:
            self._on_change(name, value)

    def _send(self, name: str) -> None:
        value, param_type = encode_value(self._params[name])
        self._mav.param_value_send(name.encode("ascii"), value, param_type, len(self._names), self._names.index(name))

    def _tell(self, severity: int, text: str) -> None:
        logger.info("%s", text)
        if self._statustext is not None:
            self._statustext(severity, text)


def _clean(param_id) -> str:
    if isinstance(param_id, bytes):
        param_id = param_id.decode("ascii", "replace")
    return param_id.split("\x00", 1)[0].strip()


def px4_parameters(takeoff_altitude: float, cruise_speed: float, max_speed: float, system_id: int) -> list[Parameter]:
    """The PX4 parameters the simulated vehicle serves, seeded from the simulation's configuration."""
    return [
        Parameter(
            "MIS_TAKEOFF_ALT",
            takeoff_altitude,
            minimum=0.0,
            maximum=80.0,
            description="take-off altitude above home (m) of NAV_TAKEOFF without altitude",
        ),
        Parameter(
            "MPC_XY_CRUISE",
            cruise_speed,
            minimum=0.5,
            maximum=max(max_speed, 0.5),
            description="default horizontal speed of repositions and missions (m/s)",
        ),
        Parameter("MPC_XY_VEL_MAX", max_speed, minimum=0.5, maximum=50.0, description="maximum horizontal speed (m/s)"),
        Parameter(
            "NAV_ACC_RAD", 2.0, minimum=0.05, maximum=200.0, description="acceptance radius of mission waypoints (m)"
        ),
        Parameter(
            "COM_OF_LOSS_T",
            1.0,
            minimum=0.0,
            maximum=60.0,
            description="offboard setpoints may pause this long (s, wall time) before failsafe",
        ),
        Parameter(
            "MAV_SYS_ID",
            float(system_id),
            is_int=True,
            minimum=1,
            maximum=250,
            description="MAVLink system id (takes effect on restart)",
        ),
        Parameter(
            "MAV_TYPE",
            float(mavlink.MAV_TYPE_QUADROTOR),
            is_int=True,
            minimum=mavlink.MAV_TYPE_QUADROTOR,
            maximum=mavlink.MAV_TYPE_QUADROTOR,
            description="vehicle type: quadrotor (fixed)",
        ),
    ]
