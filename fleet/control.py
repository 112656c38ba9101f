"""The operator's side of a fleet: a command (pause, resume, abort, status, inhibit, answer...) sent as a Zenoh
query on ``aeroexec/<fleet>/<drone>/command``, from a session with the operator's identity (the router lets only
operators query) and with the fleet's token (the second factor); one answer per drone."""

from __future__ import annotations

import json
from typing import Any

from aeroexec.fleet.credentials import CredentialsError, Identity
from aeroexec.fleet.payloads import VERSION, check_name, key
from aeroexec.fleet.transport import TransportError, open_session

TIMEOUT = 8.0  # wall seconds to wait for the drones' answers


class FleetCommandError(RuntimeError):
    """The fleet cannot be reached or refused the command as a whole."""


def command_fleet(endpoints: list[str], fleet: str, token: str, command: str, argument: str = "",
                  drone: str = "*", timeout: float = TIMEOUT,
                  identity: Identity | None = None) -> dict[str, dict[str, Any]]:
    """Each answering drone's answer (``ok``, ``message`` or ``error``, ``status`` for status); ``identity``: the
    operator's (None only for a fleet without credentials)."""
    check_name(fleet, "the fleet name")
    if drone != "*":
        check_name(drone, "the drone name")
    if not endpoints:
        raise FleetCommandError("no endpoint for the fleet: give --connect ENDPOINT")
    try:
        session = open_session("client", connect=endpoints,
                               identity=identity.read(fleet) if identity is not None else None)
    except (TransportError, CredentialsError) as error:
        raise FleetCommandError(str(error)) from None
    answers: dict[str, dict[str, Any]] = {}
    try:
        request = json.dumps({"v": VERSION, "token": token, "command": command, "argument": argument})
        for reply in session.get(key(fleet, drone, "command"), payload=request.encode(), timeout=timeout):
            sample = reply.ok if reply.ok is not None else reply.err
            try:
                answer = json.loads(bytes(sample.payload))
            except (ValueError, UnicodeDecodeError, RecursionError):
                text = bytes(sample.payload).decode(errors="replace")
                if text == "Timeout":
                    continue
                answer = {"ok": False, "error": text}
            if reply.ok is None and "drone" not in answer or answer.get("drone") == "fleet":
                raise FleetCommandError(f"refused: {answer.get('error', 'no reason given')}")
            answers[str(answer.get("drone", str(sample.key_expr).split("/")[2] if reply.ok else "?"))] = answer
    finally:
        session.close()
    return answers
