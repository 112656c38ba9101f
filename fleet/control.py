"""The operator's side of a fleet: a command (pause, resume, abort, status, inhibit, answer...) sent as a Zenoh
query on ``aeroexec/<fleet>/<drone>/command`` (``*`` for every drone), from a session with the operator's identity
(the router lets only operators query) and with the fleet's token (the second factor); one answer per drone.

Every router the operator names is a path: the command goes through each at once, on a session of its own, and each
drone's first answer counts (a drone runs a command once, whichever path brought it first: the command's ``id``).
Over a lossy network a path stalls while TCP retransmits; another path seldom stalls at the same time.

Which drones should answer: the fleet's members the caller knows (its ``fleet.json``), and those the answering
drones know (the first drone of each process names its fleet's members, ``fleet``); each of them that did not
answer gets an answer of its own, ``{ok: false, answered: false}``."""

from __future__ import annotations

import json
import logging
import threading
import time
import uuid
from collections.abc import Iterable
from typing import Any

from aeroexec.fleet.credentials import CredentialsError, Identity
from aeroexec.fleet.payloads import VERSION, check_name, key
from aeroexec.fleet.transport import TransportError, close_session, open_session

logger = logging.getLogger(__name__)

TIMEOUT = 8.0  # wall seconds to wait for the drones' answers
CLOSE_LIMIT = 5.0  # wall seconds to wait for the paths' sessions to close
OPEN_LIMIT = 60.0  # wall seconds to wait for a path to open, when none did yet


class FleetCommandError(RuntimeError):
    """The fleet cannot be reached or refused the command as a whole."""


def command_fleet(endpoints: list[str], fleet: str, token: str, command: str, argument: str = "",
                  drone: str = "*", timeout: float = TIMEOUT, identity: Identity | None = None,
                  members: Iterable[str] = ()) -> dict[str, dict[str, Any]]:
    """Each drone's answer (``ok``, ``message`` or ``error``, ``status`` for status); ``endpoints``: the routers,
    each a path the command takes at once; ``identity``: the operator's (None only for a fleet without
    credentials); ``members``: the drones the caller knows of, each expected to answer a command to every drone
    (``drone`` ``*``). A drone expected that did not answer has ``{ok: false, answered: false, error}``. Each
    answer has ``reached``: the seconds from the command's first sending (on the path that opened first) to its
    first arrival at the drone, by any path (the operator's wall clock against the drone's: equal on one machine,
    as close as their clocks are on two)."""
    check_name(fleet, "the fleet name")
    if drone != "*":
        check_name(drone, "the drone name")
    paths = list(dict.fromkeys(endpoints))
    if not paths:
        raise FleetCommandError("no endpoint for the fleet: give --connect ENDPOINT")
    try:
        material = identity.read(fleet) if identity is not None else None
    except CredentialsError as error:
        raise FleetCommandError(str(error)) from None
    asked = _Asked(drone, members, len(paths))
    request = {"v": VERSION, "token": token, "command": command, "argument": argument, "id": uuid.uuid4().hex}
    threads = [threading.Thread(target=asked.send, args=(path, fleet, request, material, timeout), daemon=True,
                                name=f"aeroexec-ctl-{n}") for n, path in enumerate(paths)]
    for thread in threads:
        thread.start()
    try:
        answers = asked.wait(timeout)
    finally:
        asked.close()
    for name in sorted(asked.expected() - set(answers)):
        answers[name] = {"ok": False, "answered": False,
                         "error": "did not answer: not reached, or no longer flying"}
    return answers


class _Asked:
    """One command's answers gathered from its paths: the first answer of each drone."""

    def __init__(self, drone: str, members: Iterable[str], paths: int) -> None:
        self.drone, self.members, self.paths = drone, set(members), paths
        self.answers: dict[str, dict[str, Any]] = {}
        self.opened = 0  # paths whose session opened
        self.ended = 0  # paths done: their query ended, or their session did not open
        self.errors: list[str] = []  # why a path did not open
        self.refused: str | None = None
        self.sessions: list[Any] = []
        self.first_open: float | None = None
        self.sent: float | None = None  # the operator's wall clock when the first path sent the command
        self._closed = False
        self._changed = threading.Condition()

    def expected(self) -> set[str]:
        """The drones that should answer: the one asked, or the members known and those the answers name."""
        if self.drone != "*":
            return {self.drone}
        return self.members | {name for answer in list(self.answers.values()) for name in answer.get("fleet", ())
                               if isinstance(name, str)}

    def send(self, endpoint: str, fleet: str, request: dict[str, Any], material: Any, timeout: float) -> None:
        """One path: a session to ``endpoint``, the query through it, its answers gathered (a thread)."""
        try:
            session = open_session("client", connect=[endpoint], identity=material)
        except TransportError as error:
            with self._changed:
                self.errors.append(str(error))
                self.ended += 1
                self._changed.notify_all()
            return
        with self._changed:
            if self._closed:
                close_session(session)
                return
            self.sessions.append(session)
            self.opened += 1
            if self.first_open is None:
                self.first_open = time.monotonic()
            self._changed.notify_all()
        with self._changed:  # sent: the command's first sending, on whichever path opened first
            self.sent = self.sent if self.sent is not None else time.time()
            payload = json.dumps({**request, "sent": self.sent}).encode()
        try:
            import zenoh  # the session opened: the extra is there

            # each answer as it arrives: Zenoh's default consolidation holds a query's replies until every route
            # ended, so one stalled router held back every drone's answer
            for reply in session.get(key(fleet, self.drone, "command"), payload=payload, timeout=timeout,
                                     consolidation=zenoh.ConsolidationMode.NONE):
                self._take(reply)
        except Exception as error:  # the session closed under the query once the command was answered
            logger.debug("fleet %s: a path through %s ended: %s", fleet, endpoint, error)
        finally:
            with self._changed:
                self.ended += 1
                self._changed.notify_all()

    def _take(self, reply: Any) -> None:
        sample = reply.ok if reply.ok is not None else reply.err
        try:
            answer = json.loads(bytes(sample.payload))
        except (ValueError, UnicodeDecodeError, RecursionError):
            text = bytes(sample.payload).decode(errors="replace")
            if text == "Timeout":
                return
            answer = {"ok": False, "error": text}
        with self._changed:
            if reply.ok is None and "drone" not in answer or answer.get("drone") == "fleet":
                self.refused = self.refused or f"refused: {answer.get('error', 'no reason given')}"
            else:
                name = str(answer.get("drone", str(sample.key_expr).split("/")[2] if reply.ok else "?"))
                self.answers.setdefault(name, answer)
            self._changed.notify_all()

    def _done(self) -> bool:
        if self.refused is not None or self.ended == self.paths:
            return True
        expected = self.expected()
        return bool(expected) and expected <= set(self.answers)

    def wait(self, timeout: float) -> dict[str, dict[str, Any]]:
        """The answers once every expected drone answered, every path ended, or ``timeout`` seconds passed since
        the first path opened; FleetCommandError when no path opened or the fleet refused the command."""
        with self._changed:
            while not self._done():
                if self.first_open is None:  # each path's connecting gives up by itself (the transport's retry)
                    if not self._changed.wait(OPEN_LIMIT) and self.first_open is None:
                        break
                    continue
                left = self.first_open + timeout - time.monotonic()
                if left <= 0:
                    break
                self._changed.wait(left)
            if self.refused is not None:
                raise FleetCommandError(self.refused)
            if self.opened == 0:
                raise FleetCommandError("; ".join(dict.fromkeys(self.errors)) or
                                        f"no router of the fleet answered within {OPEN_LIMIT:g} s")
            return dict(self.answers)

    def close(self) -> None:
        """Every path's session closed, side by side (closing a link that lost packets waits for it), within
        CLOSE_LIMIT seconds: what the command did is done either way."""
        with self._changed:
            self._closed = True
            sessions, self.sessions = self.sessions, []
        closing = [threading.Thread(target=close_session, args=(session,), daemon=True) for session in sessions]
        for thread in closing:
            thread.start()
        end = time.monotonic() + CLOSE_LIMIT
        for thread in closing:
            thread.join(max(0.0, end - time.monotonic()))
