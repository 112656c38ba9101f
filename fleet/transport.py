"""Zenoh sessions as aeroexec opens them: explicit endpoints on the loopback by default, no multicast scouting, and
for a fleet with credentials, mutual TLS and the router's access-control rules.

Zenoh's defaults listen on every interface and scout by multicast; here nothing leaves 127.0.0.1 unless the
user passes an endpoint. With an identity (:class:`~aeroexec.fleet.credentials.Material`) every endpoint is
``tls/``: the session shows its certificate, checks the other side's against the fleet's CA (and a router's
against the address it is reached at), and a listening session refuses peers without a certificate of the fleet.
Zenoh's own logging stays off (it would write to stdout).
"""

from __future__ import annotations

import base64
import json
import logging
import random
import socket
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from aeroexec.fleet.credentials import Material

from aeroexec.extras import require

logger = logging.getLogger(__name__)

DEFAULT_ENDPOINT = "tls/127.0.0.1:7447"
LEASE_MS = 2000  # a frozen process is dropped by the router after this (liveliness); telemetry says more
#: The lease of a session with an endpoint off the loopback (another machine): Zenoh's default. Over a real network
#: a link's keep-alives wait behind TCP's retransmissions; with 200 ms of latency and 20 % loss they came more than
#: 2 s late, every link between hosts was closed and opened again, and what it carried then was lost (the
#: operator's commands reached no drone: tests/fleet/test_fleet_network.py).
NETWORK_LEASE_MS = 10000
#: How long a client (the operator's ``ctl``) keeps trying to open its link to a router on another machine, and how
#: soon it tries again: over 200 ms of latency and 20 % loss one TLS handshake can fail, and a single try made
#: ``ctl`` answer "cannot open the fleet link" while the router was there (tests/fleet/test_fleet_network.py in CI).
NETWORK_CONNECT_MS = 15000
NETWORK_RETRY = {"period_init_ms": 250, "period_max_ms": 2000, "period_increase_factor": 2}
#: Bytes a Zenoh batch holds (Zenoh's default: 65535). A fleet puts its drones' ticks at the end of each period,
#: a burst; in full-size batches the first tick waited for the next 150 to fill its batch (median put -> arrival
#: 2 ms at 500 drones over 2 workers, 1.1 ms with 8 KB batches, the CPU the same: bench/fleet.py).
TX_BATCH = 8192


class TransportError(RuntimeError):
    """A Zenoh session that cannot be opened, phrased for the operator."""


def free_port(kind: int = socket.SOCK_STREAM) -> int:
    """A port of the loopback free now for ``kind`` (TCP, or ``socket.SOCK_DGRAM``), below the system's ephemeral
    range: a port the system picked for us there may be handed out again as another socket's source port (a
    Zenoh client's, a MAVLink ``udpout``'s) before we listen on it."""
    low = _ephemeral_low()
    generator = random.SystemRandom()
    for _ in range(200):
        port = generator.randrange(max(1024, low - 12000), low)
        with socket.socket(socket.AF_INET, kind) as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
            return port
    with socket.socket(socket.AF_INET, kind) as probe:  # a crowded range: the system's choice, as a last resort
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _ephemeral_low() -> int:
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range", encoding="ascii") as ports:
            return int(ports.read().split()[0])
    except (OSError, ValueError, IndexError):
        return 32768  # Linux's default; BSDs and Windows start at 49152, above it


def free_endpoint(protocol: str = "tcp") -> str:
    """An endpoint on a port of the loopback that is free now (``tcp``, or ``tls`` for a fleet with credentials)."""
    return f"{protocol}/127.0.0.1:{free_port()}"


def endpoint_host(endpoint: str) -> str:
    """The host of ``tls/HOST:PORT`` (an IPv6 address without its brackets)."""
    address = endpoint.split("/", 1)[-1].split("#")[0]
    host = address.rsplit(":", 1)[0]
    return host[1:-1] if host.startswith("[") and host.endswith("]") else host


def lease_ms(endpoints: list[str]) -> int:
    """The lease of a session on ``endpoints``: :data:`LEASE_MS` on the loopback alone, else
    :data:`NETWORK_LEASE_MS`."""
    local = all(endpoint_host(e) in ("localhost", "::1") or endpoint_host(e).startswith("127.") for e in endpoints)
    return LEASE_MS if local else NETWORK_LEASE_MS


def config(mode: str, listen: list[str] | tuple[str, ...] = (), connect: list[str] | tuple[str, ...] = (),
           identity: Material | None = None, access: dict[str, Any] | None = None) -> Any:
    """A ``zenoh.Config``: ``mode`` peer, client or router; every endpoint explicit; no multicast scouting;
    mutual TLS with ``identity``; ``access``: the access-control rules a listening session enforces."""
    with require("fleet"):
        import zenoh

    for endpoint in (*listen, *connect):
        if not isinstance(endpoint, str) or "/" not in endpoint:
            raise TransportError(f"{endpoint!r} is no Zenoh endpoint (e.g. {DEFAULT_ENDPOINT})")
        if identity is not None and not endpoint.startswith("tls/"):
            raise TransportError(f"{endpoint} is not authenticated: a fleet's endpoints are tls/HOST:PORT "
                                 f"(e.g. {DEFAULT_ENDPOINT})")
    c = zenoh.Config()
    c.insert_json5("mode", json.dumps(mode))
    c.insert_json5("scouting/multicast/enabled", "false")
    c.insert_json5("scouting/delay", "0")
    c.insert_json5("listen/endpoints", json.dumps(list(listen)))
    c.insert_json5("connect/endpoints", json.dumps(list(connect)))
    c.insert_json5("transport/link/tx/lease", str(lease_ms([*listen, *connect])))
    if mode == "client" and connect and lease_ms(list(connect)) == NETWORK_LEASE_MS:
        c.insert_json5("connect/timeout_ms", str(NETWORK_CONNECT_MS))
        c.insert_json5("connect/retry", json.dumps(NETWORK_RETRY))
    c.insert_json5("transport/link/tx/batch_size", str(TX_BATCH))
    if mode == "peer":
        c.insert_json5("scouting/gossip/enabled", "false")
    if identity is not None:
        c.insert_json5("transport/link/tls", json.dumps(_tls(identity, bool(listen), bool(connect))))
    if access is not None:
        c.insert_json5("access_control", json.dumps(access))
    return c


def _tls(identity: Material, listening: bool, connecting: bool) -> dict[str, Any]:
    def b64(data: bytes) -> str:
        return base64.b64encode(data).decode()

    tls: dict[str, Any] = {"root_ca_certificate_base64": b64(identity.ca), "enable_mtls": True,
                           "verify_name_on_connect": True, "close_link_on_expiration": True}
    if listening:
        tls |= {"listen_certificate_base64": b64(identity.certificate), "listen_private_key_base64": b64(identity.key)}
    if connecting:
        tls |= {"connect_certificate_base64": b64(identity.certificate),
                "connect_private_key_base64": b64(identity.key)}
    return tls


def close_session(session: Any, what: str = "the fleet link") -> None:
    """Close a Zenoh session; a close that does not finish (Zenoh's "close operation timed out" when a link's peer
    is cut off or slow) is a warning, never an error of the command that used it: what it did is done."""
    try:
        session.close()
    except Exception as error:  # zenoh.ZError; closing twice
        logger.warning("%s did not close cleanly: %s", what, error)


def open_session(mode: str, listen: list[str] | tuple[str, ...] = (), connect: list[str] | tuple[str, ...] = (),
                 identity: Material | None = None, access: dict[str, Any] | None = None) -> Any:
    """An open Zenoh session; :class:`TransportError` when it cannot listen or connect. Close it when done."""
    with require("fleet"):  # every Zenoh session starts here: without the extra, the pip line that adds it
        import zenoh

    try:
        return zenoh.open(config(mode, listen, connect, identity, access))
    except zenoh.ZError as error:
        where = ", ".join([*(f"listen on {e}" for e in listen), *(f"connect to {e}" for e in connect)])
        reason = str(error).split("  at ")[0].split(" at /")[0].rstrip(". ")  # not Zenoh's source location
        if identity is not None and connect and "connect" in reason:
            reason += (f" (as {identity.name}: is the router running there, with a certificate of this fleet's CA "
                       f"that names {', '.join(sorted({endpoint_host(e) for e in connect}))}?)")
        raise TransportError(f"cannot open the fleet link ({where or mode}): {reason}") from None
