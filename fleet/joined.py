"""One drone joined to a fleet from its own process (``aeroexec run --fleet``): a Zenoh client of the router."""

from __future__ import annotations

import logging
import os
import secrets
from pathlib import Path
from typing import Any

from aeroexec.fleet import members
from aeroexec.fleet.fleet_json import FLEET_FILE, TOKEN_VARIABLE, write_fleet_file
from aeroexec.fleet.link import FleetLink
from aeroexec.fleet.payloads import check_name
from aeroexec.fleet.transport import DEFAULT_ENDPOINT, TransportError, close_session

logger = logging.getLogger(__name__)


class JoinedFleet:
    """One drone's engine on a fleet from its own process: the session, the node and the link; close it."""

    def __init__(self, session: Any, node: Any, link: Any, folder: Path) -> None:
        self.session, self.node, self.link, self.folder = session, node, link, folder

    def close(self) -> None:
        """The drone out of the fleet; the session closed whatever failed before (a session left open at the exit
        may call into Python, its queryable's callbacks, while the interpreter finalizes: the process aborts)."""
        try:
            self.link.leave()
            self.node.close()
        finally:
            close_session(self.session)
            (self.folder / FLEET_FILE).unlink(missing_ok=True)


def join_fleet(engine: Any, fleet: str, name: str, folder: Path, mission: str, connect: list[str] | None = None,
               token: str | None = None, share: tuple[str, ...] = (), credentials: str | None = None,
               trust: dict[str, int] | None = None) -> JoinedFleet:
    """Join ``engine`` to ``fleet`` as ``name`` through ``connect`` (a client of the router) with the identity at
    ``credentials``; ``trust``: predicate -> how many distinct members must say a belief of it (the fleet file's
    ``trust:``, which this process does not read); ValueError (CredentialsError) or :class:`TransportError` when it
    cannot."""
    fleet, name = check_name(fleet, "--fleet"), check_name(name, "--name")
    if not credentials:
        raise ValueError(f"--fleet needs --credentials DIR: the folder of {name}.pem, {name}.key and the fleet's "
                         f"ca.pem (aeroexec fleet FLEET.yaml --make-credentials DIR)")
    token = token or os.environ.get(TOKEN_VARIABLE) or secrets.token_hex(16)
    endpoints = connect or [DEFAULT_ENDPOINT]
    try:
        membership = members.join(fleet, name, credentials, endpoints)
    except TransportError as error:
        raise TransportError(f"{error} (is `aeroexec fleet FLEET.yaml --router` running?)") from None
    session = membership.session
    node = membership.node(token)
    link = FleetLink(node, name, engine, tuple(share), trust=trust).join()
    link.mission = mission
    write_fleet_file(folder, fleet, endpoints, token, membership.operator, (name,))
    logger.info("%s joined fleet %s through %s", name, fleet, ", ".join(endpoints))
    return JoinedFleet(session, node, link, folder)
