"""Free UDP ports for the tests' MAVLink links, outside the system's ephemeral range (see ``free_port``)."""

from __future__ import annotations

import socket

from aeroexec.fleet.transport import free_port


def free_udp_port() -> int:
    return free_port(socket.SOCK_DGRAM)
