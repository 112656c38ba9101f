"""The operator's side of a fleet: a command (pause, resume, abort, status, inhibit, answer...) sent as a Zenoh
query on ``aeroexec/<fleet>/<drone>/command`` (``*`` for every drone), from a session with the operator's identity
(the router lets only operators query) and with the fleet's token (the second factor); one answer per drone.

Every router the operator names is a path: the command goes through each at once, on a session of its own, and each
drone's first answer counts (a drone runs a command once, whichever path brought it first: the command's ``id``).
Over a lossy network a path stalls while TCP retransmits; another path seldom stalls at the same time.

Nothing of Zenoh outlives :meth:`FleetOperator.close`: every path's session is closed, which ends the queries still
running (a path's copy of a command answered by the other), and every thread the operator started (a path opening,
a query's answers, a session closing) is joined. Zenoh's calls release the GIL: a thread still inside one when the
interpreter finalizes is ended by ``pthread_exit`` on its way back, through Zenoh's Rust frames, which abort the
process ("FATAL: exception not rethrown", SIGABRT) after the command was done; and Zenoh cannot be called at process
exit (``atexit``). Each wait is bounded by Zenoh's own limits: its connect timeout, a query's ``timeout``, its close
timeout.

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
OPEN_LIMIT = 60.0  # wall seconds to wait for a path to open, when none did yet


class FleetCommandError(RuntimeError):
    """The fleet cannot be reached or refused the command as a whole."""


def command_fleet(endpoints: list[str], fleet: str, token: str, command: str, argument: str = "",
                  drone: str = "*", timeout: float = TIMEOUT, identity: Identity | None = None,
                  members: Iterable[str] = ()) -> dict[str, dict[str, Any]]:
    """One command through a :class:`FleetOperator` opened for it (``aeroexec ctl --fleet``): see
    :meth:`FleetOperator.command`."""
    with FleetOperator(endpoints, fleet, token, identity, members) as operator:
        return operator.command(command, argument, drone, timeout)


class FleetOperator:
    """The operator's links to a fleet: one session per router of ``endpoints`` (each a path), opened side by side
    and kept open; each command goes through every open path at once. ``identity``: the operator's (None only for
    a fleet without credentials); ``members``: the drones the operator knows of, each expected to answer a command
    to every drone. Kept open (``aeroexec ctl --fleet NAME --stdin``), a command goes out at once on every path,
    none of them waiting for TCP's, TLS's and Zenoh's handshakes (seconds over a slow, lossy network)."""

    def __init__(self, endpoints: list[str], fleet: str, token: str, identity: Identity | None = None,
                 members: Iterable[str] = ()) -> None:
        self.fleet, self.token, self.members = check_name(fleet, "the fleet name"), token, list(members)
        self.paths = list(dict.fromkeys(endpoints))
        if not self.paths:
            raise FleetCommandError("no endpoint for the fleet: give --connect ENDPOINT")
        try:
            self._material = identity.read(fleet) if identity is not None else None
        except CredentialsError as error:
            raise FleetCommandError(str(error)) from None
        self.sessions: list[Any] = []
        self._errors: list[str] = []
        self._failed = 0
        self._asked: list[_Asked] = []  # the commands waiting for answers: a path that opens carries them too
        self._closed = False
        self._changed = threading.Condition()
        #: the threads started, joined by close: none is a daemon (the interpreter waits for them rather than end
        #: them inside Zenoh)
        self._threads = [threading.Thread(target=self._open, args=(endpoint,), name=f"aeroexec-ctl-{n}")
                         for n, endpoint in enumerate(self.paths)]
        for thread in self._threads:
            thread.start()

    def __enter__(self) -> FleetOperator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _open(self, endpoint: str) -> None:
        try:
            session = open_session("client", connect=[endpoint], identity=self._material)
        except TransportError as error:
            with self._changed:
                self._errors.append(str(error))
                self._failed += 1
                self._changed.notify_all()
                asked = list(self._asked)
            for one in asked:  # a command whose paths all ended ends now, none opening any more
                one.wake()
            return
        with self._changed:
            if self._closed:
                close_session(session)
                return
            self.sessions.append(session)
            asked = list(self._asked)
            self._changed.notify_all()
        for one in asked:
            one.send(session, self.fleet)

    def started(self, thread: threading.Thread) -> None:
        """``thread`` (one of a query's answers) started: :meth:`close` joins it."""
        thread.start()
        with self._changed:
            self._threads = [t for t in self._threads if t.is_alive()] + [thread]

    def opening(self) -> bool:
        """Whether a path is still opening."""
        return len(self.sessions) + self._failed < len(self.paths)

    def command(self, command: str, argument: str = "", drone: str = "*",
                timeout: float = TIMEOUT) -> dict[str, dict[str, Any]]:
        """Each drone's answer (``ok``, ``message`` or ``error``, ``status`` for status). A drone expected that did
        not answer has ``{ok: false, answered: false, error}``. Each answer has ``reached``: the seconds from the
        command's first sending to its first arrival at the drone, by any path (the operator's wall clock against
        the drone's: equal on one machine, as close as their clocks are on two)."""
        if drone != "*":
            check_name(drone, "the drone name")
        request = {"v": VERSION, "token": self.token, "command": command, "argument": argument,
                   "id": uuid.uuid4().hex}
        asked = _Asked(self, drone, request, timeout)
        with self._changed:  # the first path open (each gives up by itself: the transport's retry)
            if not self._changed.wait_for(lambda: self.sessions or not self.opening(), OPEN_LIMIT):
                raise FleetCommandError(f"no router of the fleet answered within {OPEN_LIMIT:g} s")
            if not self.sessions:
                raise FleetCommandError("; ".join(dict.fromkeys(self._errors)))
            sessions = list(self.sessions)
            self._asked.append(asked)
        try:
            for session in sessions:
                asked.send(session, self.fleet)
            answers = asked.wait()
        finally:
            with self._changed:
                self._asked.remove(asked)
        for name in sorted(asked.expected() - set(answers)):
            answers[name] = {"ok": False, "answered": False,
                             "error": "did not answer: not reached, or no longer flying"}
        return answers

    def close(self) -> None:
        """Every path's session closed, side by side (closing a link that lost packets waits for it, at most
        Zenoh's close timeout: then a warning, what the commands did is done either way), and every thread of the
        operator joined: the queries end with their sessions, a path still opening closes its session itself."""
        with self._changed:
            self._closed = True
            sessions, self.sessions = self.sessions, []
        closing = [threading.Thread(target=close_session, args=(session,), name="aeroexec-ctl-close")
                   for session in sessions]
        for thread in closing:
            thread.start()
        for thread in closing:
            thread.join()
        while True:  # a path that opened meanwhile may have sent a command on a thread of its own: that one too
            with self._changed:
                left = [thread for thread in self._threads if thread.is_alive()]
            if not left:
                return
            for thread in left:
                thread.join()


class _Asked:
    """One command's answers gathered from its paths: the first answer of each drone."""

    def __init__(self, operator: FleetOperator, drone: str, request: dict[str, Any], timeout: float) -> None:
        self.operator, self.drone, self.request, self.timeout = operator, drone, request, timeout
        self.answers: dict[str, dict[str, Any]] = {}
        self.started = 0  # paths it was sent on
        self.ended = 0  # of them, those whose query ended
        self.refused: str | None = None
        self.sent: float | None = None  # the operator's wall clock when the first path sent it
        self.first: float | None = None  # the same, on the monotonic clock
        self._changed = threading.Condition()

    def expected(self) -> set[str]:
        """The drones that should answer: the one asked, or the members known and those the answers name."""
        if self.drone != "*":
            return {self.drone}
        return set(self.operator.members) | {name for answer in list(self.answers.values())
                                             for name in answer.get("fleet", ()) if isinstance(name, str)}

    def send(self, session: Any, fleet: str) -> None:
        """The query through one path's ``session``; its answers gathered on a thread of its own."""
        with self._changed:  # sent: the command's first sending, on whichever path it went first
            if self.sent is None:
                self.sent, self.first = time.time(), time.monotonic()
            self.started += 1
            payload = json.dumps({**self.request, "sent": self.sent}).encode()
        self.operator.started(threading.Thread(target=self._gather, args=(session, fleet, payload),
                                               name="aeroexec-ctl-answers"))

    def _gather(self, session: Any, fleet: str, payload: bytes) -> None:
        try:
            import zenoh  # a session opened: the extra is there

            # each answer as it arrives: Zenoh's default consolidation holds a query's replies until every route
            # ended, so one stalled router held back every drone's answer
            for reply in session.get(key(fleet, self.drone, "command"), payload=payload, timeout=self.timeout,
                                     consolidation=zenoh.ConsolidationMode.NONE):
                self._take(reply)
        except Exception as error:  # the session closed under the query once the command was answered (close)
            logger.debug("fleet %s: a path's query ended: %s", fleet, error)
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

    def wake(self) -> None:
        """Look again whether the command is done (a path stopped opening)."""
        with self._changed:
            self._changed.notify_all()

    def _done(self) -> bool:
        if self.refused is not None or self.ended == self.started and not self.operator.opening():
            return True
        expected = self.expected()
        return bool(expected) and expected <= set(self.answers)

    def wait(self) -> dict[str, dict[str, Any]]:
        """The answers once every expected drone answered, every path's query ended, or ``timeout`` seconds
        passed since the first sending; FleetCommandError when the fleet refused the command."""
        with self._changed:
            first = self.first if self.first is not None else time.monotonic()
            while not self._done():
                left = first + self.timeout - time.monotonic()
                if left <= 0:
                    break
                self._changed.wait(left)
            if self.refused is not None:
                raise FleetCommandError(self.refused)
            return dict(self.answers)
