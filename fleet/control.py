"""The operator's side of a fleet: a command (pause, resume, abort, status, inhibit, answer...) sent as a Zenoh
query on ``aeroexec/<fleet>/<drone>/command`` (``*`` for every drone), from a session with the operator's identity
(the router lets only operators query) and with the fleet's token (the second factor); one answer per drone.

Which drones should answer: the fleet's members the caller knows (its ``fleet.json``), and those the answering
drones know (the first drone of each process names its fleet's members, ``fleet``); each of them that did not
answer gets an answer of its own, ``{ok: false, answered: false}``."""

from __future__ import annotations

import json
import time
from collections.abc import Iterable
from typing import Any

from aeroexec.fleet.credentials import CredentialsError, Identity
from aeroexec.fleet.payloads import VERSION, check_name, key
from aeroexec.fleet.transport import TransportError, close_session, open_session

TIMEOUT = 8.0  # wall seconds to wait for the drones' answers


class FleetCommandError(RuntimeError):
    """The fleet cannot be reached or refused the command as a whole."""


def command_fleet(endpoints: list[str], fleet: str, token: str, command: str, argument: str = "",
                  drone: str = "*", timeout: float = TIMEOUT, identity: Identity | None = None,
                  members: Iterable[str] = ()) -> dict[str, dict[str, Any]]:
    """Each drone's answer (``ok``, ``message`` or ``error``, ``status`` for status); ``identity``: the operator's
    (None only for a fleet without credentials); ``members``: the drones the caller knows of, each expected to
    answer a command to every drone (``drone`` ``*``). A drone expected that did not answer has
    ``{ok: false, answered: false, error}``. Each answer has ``reached``: the seconds from the command's sending to
    its arrival at the drone (the operator's wall clock against the drone's: equal on one machine, as close as
    their clocks are on two)."""
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
        request = json.dumps({"v": VERSION, "token": token, "command": command, "argument": argument,
                              "sent": time.time()})
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
        close_session(session)
    expected = {drone} if drone != "*" else set(members) | {
        name for answer in answers.values() for name in answer.get("fleet", ()) if isinstance(name, str)}
    for name in sorted(expected - set(answers)):
        answers[name] = {"ok": False, "answered": False,
                         "error": "did not answer: not reached, or no longer flying"}
    return answers
