"""Zenoh sessions as aeroexec opens them: explicit endpoints on the loopback by default, no multicast scouting.

Zenoh's defaults listen on every interface and scout by multicast; here nothing leaves 127.0.0.1 unless the
user passes an endpoint. Zenoh's own logging stays off (it would write to stdout).
"""

from __future__ import annotations

import json
import logging
import socket

from aeroexec.extras import require

logger = logging.getLogger(__name__)

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
LEASE_MS = 2000  # a frozen process is dropped by the router after this (liveliness); telemetry says more


class TransportError(RuntimeError):
    """A Zenoh session that cannot be opened, phrased for the operator."""


def free_endpoint() -> str:
    """A TCP endpoint on a port of the loopback that is free now (tests)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{probe.getsockname()[1]}"


def config(mode: str, listen: list[str] | tuple[str, ...] = (), connect: list[str] | tuple[str, ...] = ()):
    """A ``zenoh.Config``: ``mode`` peer, client or router; every endpoint explicit; no multicast scouting."""
    with require("fleet"):
        import zenoh

    for endpoint in (*listen, *connect):
        if not isinstance(endpoint, str) or "/" not in endpoint:
            raise TransportError(f"{endpoint!r} is no Zenoh endpoint (e.g. {DEFAULT_ENDPOINT})")
    c = zenoh.Config()
    c.insert_json5("mode", json.dumps(mode))
    c.insert_json5("scouting/multicast/enabled", "false")
    c.insert_json5("scouting/delay", "0")
    c.insert_json5("listen/endpoints", json.dumps(list(listen)))
    c.insert_json5("connect/endpoints", json.dumps(list(connect)))
    c.insert_json5("transport/link/tx/lease", str(LEASE_MS))
    if mode == "peer":
        c.insert_json5("scouting/gossip/enabled", "false")
    return c


def open_session(mode: str, listen: list[str] | tuple[str, ...] = (), connect: list[str] | tuple[str, ...] = ()):
    """An open Zenoh session; :class:`TransportError` when it cannot listen or connect. Close it when done."""
    with require("fleet"):  # every Zenoh session starts here: without the extra, the pip line that adds it
        import zenoh

    try:
        return zenoh.open(config(mode, listen, connect))
    except zenoh.ZError as error:
        where = ", ".join([*(f"listen on {e}" for e in listen), *(f"connect to {e}" for e in connect)])
        reason = str(error).split("  at ")[0].split(" at /")[0].rstrip(". ")  # not Zenoh's source location
        raise TransportError(f"cannot open the fleet link ({where or mode}): {reason}") from None
