"""A process's membership of a fleet: the Zenoh sessions it opens with the fleet's credentials and rules.

- :func:`listen`: the fleet's router (``aeroexec fleet FILE`` with its drones, or ``--router``): mutual TLS with the
  router's certificate and the access-control rules of the file's roster; the credentials are made in the run's
  output folder when the file names none.
- :func:`connect`: a process flying some of a fleet file's drones through its router, one session per identity
  its drones speak with (one for a process hosting them all, or one per drone).
- :func:`join`: one drone of its own process (``aeroexec run --fleet``), with its identity.
- :func:`work`: a worker process of the fleet's own (``aeroexec fleet --workers``), flying its share of the drones
  through the router that started it, with the router's identity (it speaks for every drone, as the router does).
- :func:`make_credentials`: every credential a fleet file needs, for several machines.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.fleet import credentials as creds
from aeroexec.fleet.access import Roster, access_control
from aeroexec.fleet.credentials import Authority, CredentialsError, Identity, Material, common_name
from aeroexec.fleet.fleet_file import FleetSpec
from aeroexec.fleet.node import FleetNode
from aeroexec.fleet.transport import endpoint_host, open_session

logger = logging.getLogger(__name__)

CREDENTIALS_FOLDER = "credentials"  # in a run's output folder, when the fleet file names none
ANY_HOST = ("0.0.0.0", "::", "[::]")


@dataclass
class Membership:
    """The sessions of one process in ``fleet``: ``session`` (it hears the fleet), ``sessions`` (a local drone ->
    the session of its own identity, when not ``session``), the roster when known, the endpoints, and the
    operator's certificate an ``aeroexec ctl`` on this machine may use."""

    fleet: str
    session: Any
    endpoints: list[str]
    roster: Roster | None = None
    sessions: dict[str, Any] = field(default_factory=dict)
    operator: Path | None = None
    local: tuple[str, ...] = ()  # the drones this process flies

    def node(self, token: str) -> FleetNode:
        """The process's :class:`FleetNode` on these sessions (close it before :meth:`close`)."""
        return FleetNode(self.session, self.fleet, token, self.roster, self.sessions, self.local)

    def close(self) -> None:
        for session in {id(s): s for s in (self.session, *self.sessions.values())}.values():
            try:
                session.close()
            except Exception as error:  # closing twice, or a session Zenoh already dropped
                logger.debug("fleet %s: closing a session: %s", self.fleet, error)


def make_credentials(spec: FleetSpec, folder: Path, hosts: tuple[str, ...] = creds.LOCAL_HOSTS) -> dict[str, Identity]:
    """The fleet's CA in ``folder`` (kept if there), the router's identity for ``hosts``, every drone's identity
    (where the file names it, else in ``folder``) and the operators'; existing valid ones are kept. By name."""
    authority = Authority(folder, spec.name)
    made = {creds.ROUTER: authority.issue(creds.ROUTER, hosts=tuple(dict.fromkeys(hosts)))}
    for drone in spec.drones:
        place = spec.identity(drone, folder)
        name = spec.identity_name(drone)
        if name not in made:
            made[name] = authority.issue(name, place.certificate, place.key)
    for operator in spec.operators:
        made[operator] = authority.issue(operator)
    return made


def listen(spec: FleetSpec, endpoints: list[str], output: Path,
           routers: list[str] | tuple[str, ...] = ()) -> Membership:
    """The fleet's router on ``endpoints``, with the file's credentials or new ones in ``output/credentials``, linked
    to the fleet's ``routers`` on other machines (they show the same router identity)."""
    if spec.credentials is not None:
        if not spec.credentials.is_dir():
            raise CredentialsError(f"{spec.file}: the credentials folder {spec.credentials} is not there: make it "
                                   f"with aeroexec fleet {spec.file} --make-credentials {spec.credentials}")
        router = Identity.at(spec.credentials, creds.ROUTER)
        operator = Identity.at(spec.credentials, spec.operators[0]) if spec.operators else None
    else:
        hosts = (*creds.LOCAL_HOSTS, *(h for h in map(endpoint_host, endpoints) if h not in ANY_HOST))
        made = make_credentials(spec, output / CREDENTIALS_FOLDER, hosts)
        router, operator = made[creds.ROUTER], made.get(spec.operators[0]) if spec.operators else None
    material = _read(router, spec.name, creds.ROUTER)
    session = open_session("router", listen=endpoints, connect=routers, identity=material,
                           access=access_control(spec.roster()))
    found = operator.certificate if operator is not None and operator.certificate.exists() else None
    return Membership(spec.name, session, list(endpoints), spec.roster(), operator=found,
                      local=tuple(d.name for d in spec.flown))


def connect(spec: FleetSpec, endpoints: list[str]) -> Membership:
    """The sessions of the file's drones with missions, through the router at ``endpoints``."""
    groups: dict[Path, tuple[Identity, list[str], str]] = {}
    for drone in spec.flown:
        identity = spec.identity(drone)
        if identity is None:
            raise CredentialsError(f"{spec.file}:{drone.line}: the drone {drone.name} has no credentials to join "
                                   f"through a router: give credentials: DIR (aeroexec fleet {spec.file} "
                                   f"--make-credentials DIR), or its certificate: and key:")
        groups.setdefault(identity.certificate, (identity, [], spec.identity_name(drone)))[1].append(drone.name)
    membership = None
    try:
        for identity, drones, name in groups.values():
            session = open_session("client", connect=endpoints, identity=_read(identity, spec.name, name))
            if membership is None:
                membership = Membership(spec.name, session, list(endpoints), spec.roster(),
                                        operator=_operator_beside(spec.credentials, spec.operators),
                                        local=tuple(d.name for d in spec.flown))
            else:
                membership.sessions.update(dict.fromkeys(drones, session))
    except BaseException:
        if membership is not None:
            membership.close()
        raise
    if membership is None:
        raise CredentialsError(f"{spec.file}: no drone has a mission here: nothing joins the fleet")
    return membership


def join(fleet: str, name: str, credentials: str | Path, endpoints: list[str]) -> Membership:
    """The session of drone ``name`` with the identity at ``credentials`` (a folder holding ``name.pem``, or the
    certificate itself), through the router at ``endpoints``."""
    identity = Identity.at(credentials, name)
    material = identity.read(fleet)
    if material.name != common_name(name, fleet):
        logger.info("%s speaks as %s", name, material.name)
    folder = Path(credentials) if Path(credentials).is_dir() else identity.certificate.parent
    return Membership(fleet, open_session("client", connect=endpoints, identity=material), list(endpoints),
                      operator=_operator_beside(folder, (creds.OPERATOR,)), local=(name,))


def work(spec: FleetSpec, credentials: Path, endpoints: list[str], drones: tuple[str, ...]) -> Membership:
    """The session of a worker process flying ``drones`` of ``spec``, through the router at ``endpoints`` that made
    or read the fleet's credentials in ``credentials``."""
    material = _read(Identity.at(credentials, creds.ROUTER), spec.name, creds.ROUTER)
    return Membership(spec.name, open_session("client", connect=endpoints, identity=material), list(endpoints),
                      spec.roster(), local=drones)


def credentials_folder(spec: FleetSpec, output: Path) -> Path:
    """Where :func:`listen` finds the fleet's credentials: the file's, else those it made in ``output``."""
    return spec.credentials if spec.credentials is not None else output / CREDENTIALS_FOLDER


def operator_identity(credentials: str | Path) -> Identity:
    """The operator's identity at ``credentials`` (a folder holding ``operator.pem``, or the certificate)."""
    return Identity.at(credentials, creds.OPERATOR)


def _operator_beside(folder: Path | None, operators: tuple[str, ...]) -> Path | None:
    """The first operator's certificate in the credentials ``folder`` when this machine holds it (with its key), for
    an ``aeroexec ctl`` here; None when it is not here (a drone's machine holds only its own identity)."""
    if folder is None or not operators:
        return None
    identity = Identity.at(folder, operators[0])
    return identity.certificate if identity.certificate.is_file() and identity.key.is_file() else None


def _read(identity: Identity, fleet: str, name: str) -> Material:
    material = identity.read(fleet)
    if material.name != common_name(name, fleet):
        raise CredentialsError(f"{identity.certificate}: holds the identity {material.name}, not "
                               f"{common_name(name, fleet)}")
    return material
