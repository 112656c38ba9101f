"""What a failed MAVSDK call means for the engine: a :class:`Failure` and a sentence for the operator.

MAVSDK plugins raise ``<Plugin>Error`` exceptions carrying a ``result`` enum (ActionResult, OffboardResult,
TelemetryResult, ParamResult...). Their member names are shared across plugins, so the mapping goes by name.
"""

from __future__ import annotations

import asyncio
import concurrent.futures

from aeroexec.drones.interface import Failure

_BY_RESULT: dict[str, tuple[Failure, str]] = {
    "NO_SYSTEM": (Failure.LINK_LOST, "no vehicle is connected"),
    "CONNECTION_ERROR": (Failure.LINK_LOST, "the link to the vehicle failed"),
    "BUSY": (Failure.DENIED, "the vehicle is busy"),
    "COMMAND_DENIED": (Failure.DENIED, "the vehicle refused it"),
    "COMMAND_DENIED_LANDED_STATE_UNKNOWN": (Failure.DENIED, "the vehicle refused it: its landed state is unknown"),
    "COMMAND_DENIED_NOT_LANDED": (Failure.DENIED, "the vehicle refused it: it is not landed"),
    "TIMEOUT": (Failure.TIMEOUT, "the vehicle did not answer"),
    "UNSUPPORTED": (Failure.UNSUPPORTED, "the vehicle does not support it"),
    "VTOL_TRANSITION_SUPPORT_UNKNOWN": (Failure.UNSUPPORTED, "VTOL transitions are not known to be supported"),
    "NO_VTOL_TRANSITION_SUPPORT": (Failure.UNSUPPORTED, "the vehicle is not a VTOL"),
    "PARAMETER_ERROR": (Failure.DENIED, "the vehicle refused a parameter it needs"),
    "FAILED": (Failure.DENIED, "the vehicle failed to do it"),
    "INVALID_ARGUMENT": (Failure.DENIED, "an argument is out of range"),
    "NO_SETPOINT_SET": (Failure.DENIED, "no offboard setpoint was set"),
    "WRONG_TYPE": (Failure.DENIED, "a parameter has another type"),
    "PARAM_NAME_TOO_LONG": (Failure.DENIED, "a parameter name is too long"),
    "VALUE_UNSUPPORTED": (Failure.DENIED, "the vehicle refused a parameter value"),
}


class AdapterError(Exception):
    """A failure the adapter decides itself (not connected, no home yet...), with its :class:`Failure`."""

    def __init__(self, failure: Failure, reason: str) -> None:
        super().__init__(reason)
        self.failure = failure
        self.reason = reason


def describe_failure(command: str, exc: BaseException, link_ok: bool, status_text: str = "") -> tuple[Failure, str]:
    """The :class:`Failure` and operator sentence for ``command`` failing with ``exc``.

    ``link_ok`` False turns timeouts into LINK_LOST; ``status_text`` is the vehicle's latest STATUSTEXT,
    which autopilots use to say why they refused a command (e.g. "Arming denied: ...").
    """
    if isinstance(exc, AdapterError):
        return exc.failure, f"{command} failed: {exc.reason}"
    if isinstance(exc, (asyncio.CancelledError, concurrent.futures.CancelledError)):
        return Failure.CANCELLED, f"{command} cancelled: the drone was closed"
    result = getattr(exc, "result", None)
    name = getattr(result, "name", None)
    if name is not None:
        failure, text = _BY_RESULT.get(name, (Failure.DENIED, f"the vehicle answered {name}"))
        if failure == Failure.TIMEOUT and not link_ok:
            failure, text = Failure.LINK_LOST, "the link to the vehicle is down"
        if failure == Failure.DENIED and status_text:
            text = f"{text} ({status_text})"
        return failure, f"{command} {'denied' if failure == Failure.DENIED else 'failed'}: {text}"
    if isinstance(exc, (TimeoutError, asyncio.TimeoutError)):
        failure = Failure.TIMEOUT if link_ok else Failure.LINK_LOST
        return failure, f"{command} failed: no answer from the vehicle in time"
    if isinstance(exc, RuntimeError) and "destroyed" in str(exc):
        return Failure.CANCELLED, f"{command} cancelled: the drone was closed"
    return Failure.DENIED, f"{command} failed: {type(exc).__name__}: {exc}"
