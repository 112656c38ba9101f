"""The testbed's delaying relay: the network between the hosts of :mod:`testbed` when it has latency. Each host's
``eth0`` is a TUN device whose other end is this process: every IP packet a host sends comes here, is held
``delay ± jitter`` ms (uniform), and is written to the host it is addressed to. The kernel of each host sees a real
network: its TCP (Zenoh's links, TLS over TCP) meets the latency, retransmits what is lost and puts back in order
what arrives out of order.

Faults, set at start or on a line of standard input (each answered ``ok`` on standard output once in force):

- ``delay MS JITTER``: each packet held MS ± JITTER ms, drawn for each packet;
- ``reorder 1|0``: 1: each packet's own draw (with jitter, a later packet may overtake an earlier one); 0: a packet
  never leaves before the one sent before it to the same host;
- ``duplicate P``: P % of the packets are sent twice (each copy its own delay);
- ``host NAME NAMESPACE ADDRESS``: a new host on the network (its ``eth0`` made in NAMESPACE);
- ``cut HOST`` / ``heal HOST``: every packet from or to HOST is dropped (a partition) / no longer;
- ``stats``: ``stats {"HOST": [packets in, bytes in, packets out, bytes out], ...}`` (what the relay carried).

Packet loss is not the relay's: the testbed drops packets at each host's way in with nftables, as without latency.

    python relay.py --host a=aex1-a=10.77.0.1 --host b=aex1-b=10.77.0.2 --delay 200 --jitter 50 --duplicate 1

makes a TUN device per host, moves it into the host's namespace as ``eth0`` with its address on ``10.77.0.0/24``,
prints ``ready`` and relays until its standard input closes (or SIGTERM); the devices go with it. Root only.
"""

from __future__ import annotations

import argparse
import fcntl
import heapq
import json
import os
import random
import select
import signal
import struct
import subprocess
import sys
import time
from dataclasses import dataclass, field

TUNSETIFF = 0x400454CA
IFF_TUN = 0x0001
IFF_NO_PI = 0x1000
NIC = "eth0"


@dataclass
class Faults:
    """What the relay does to each packet."""

    delay: float = 0.0  # ms
    jitter: float = 0.0  # ms
    reorder: bool = True
    duplicate: float = 0.0  # %
    cut: set[str] = field(default_factory=set)  # host names


@dataclass
class Port:
    """One host's TUN device: its file descriptor, its address, what went through it."""

    name: str
    address: bytes  # 4 bytes
    fd: int
    counts: list[int] = field(default_factory=lambda: [0, 0, 0, 0])  # packets in, bytes in, packets out, bytes out
    last_due: float = 0.0


def _tun(name: str) -> int:
    fd = os.open("/dev/net/tun", os.O_RDWR | os.O_NONBLOCK)
    fcntl.ioctl(fd, TUNSETIFF, struct.pack("16sH", name.encode(), IFF_TUN | IFF_NO_PI))
    return fd


def _ip(*words: str) -> None:
    done = subprocess.run(["ip", *words], capture_output=True, text=True, timeout=60)
    if done.returncode != 0:
        raise OSError(f"ip {' '.join(words)}: {done.stderr.strip()}")


def make_port(device: str, host: str, namespace: str, address: str) -> Port:
    """A TUN device ``device`` moved into ``namespace`` as its ``eth0`` at ``address``/24."""
    fd = _tun(device)
    _ip("link", "set", device, "netns", namespace)
    _ip("-n", namespace, "link", "set", device, "name", NIC)
    _ip("-n", namespace, "addr", "add", f"{address}/24", "dev", NIC)
    _ip("-n", namespace, "link", "set", NIC, "up")
    return Port(host, bytes(int(part) for part in address.split(".")), fd)


class Relay:
    """Packets between ports, held and faulted as :class:`Faults` says."""

    def __init__(self, faults: Faults, prefix: str, seed: int | None = None) -> None:
        self.faults, self.prefix = faults, prefix
        self.ports: list[Port] = []
        self.by_fd: dict[int, Port] = {}
        self.by_address: dict[bytes, Port] = {}
        self.by_name: dict[str, Port] = {}
        self.random = random.Random(seed)
        self.held: list[tuple[float, int, Port, bytes]] = []
        self.count = 0

    def add(self, host: str, namespace: str, address: str) -> None:
        """Host ``host`` (namespace ``namespace``) on the network at ``address``."""
        port = make_port(f"{self.prefix}t{len(self.ports) + 1}"[-15:], host, namespace, address)
        self.ports.append(port)
        self.by_fd[port.fd], self.by_address[port.address], self.by_name[host] = port, port, port

    def command(self, line: str) -> str:
        words = line.split()
        if not words:
            return ""
        verb, rest = words[0], words[1:]
        try:
            if verb == "host":
                self.add(*rest[:3])
            elif verb == "delay":
                self.faults.delay, self.faults.jitter = float(rest[0]), float(rest[1]) if rest[1:] else 0.0
            elif verb == "reorder":
                self.faults.reorder = rest[0] == "1"
            elif verb == "duplicate":
                self.faults.duplicate = float(rest[0])
            elif verb in ("cut", "heal"):
                if rest[0] not in self.by_name:
                    return f"error: no host {rest[0]}"
                (self.faults.cut.add if verb == "cut" else self.faults.cut.discard)(rest[0])
            elif verb == "stats":
                return "stats " + json.dumps({p.name: p.counts for p in self.ports})
            else:
                return f"error: unknown command {verb}"
        except (IndexError, ValueError, TypeError, OSError) as error:
            return f"error: {line.strip()}: {error}"
        return "ok"

    def receive(self, port: Port, now: float) -> None:
        """Every packet waiting at ``port``, held for its destination (IPv4 only: the testbed's network)."""
        while True:
            try:
                packet = os.read(port.fd, 65535)
            except BlockingIOError:
                return
            if len(packet) < 20 or packet[0] >> 4 != 4:
                continue
            port.counts[0] += 1
            port.counts[1] += len(packet)
            target = self.by_address.get(packet[16:20])
            if target is None or {port.name, target.name} & self.faults.cut:
                continue
            for _ in range(2 if self.random.uniform(0, 100) < self.faults.duplicate else 1):
                self.hold(target, packet, now)

    def hold(self, target: Port, packet: bytes, now: float) -> None:
        spread = self.faults.jitter
        due = now + max(0.0, self.faults.delay + self.random.uniform(-spread, spread)) / 1000
        if not self.faults.reorder:
            due = max(due, target.last_due)
        target.last_due = max(target.last_due, due)
        self.count += 1
        heapq.heappush(self.held, (due, self.count, target, packet))

    def send_due(self, now: float) -> None:
        while self.held and self.held[0][0] <= now:
            _, _, target, packet = heapq.heappop(self.held)
            if target.name in self.faults.cut:
                continue  # cut while held: lost with the link
            try:
                os.write(target.fd, packet)
            except OSError:  # the host's link is down: lost, as on a wire
                continue
            target.counts[2] += 1
            target.counts[3] += len(packet)

    def run(self, control: int) -> None:
        pending = b""
        while True:
            readers = [control, *self.by_fd]
            now = time.monotonic()
            self.send_due(now)
            wait = max(0.0, self.held[0][0] - time.monotonic()) if self.held else None
            ready, _, _ = select.select(readers, [], [], wait)
            now = time.monotonic()
            for fd in ready:
                if fd != control:
                    self.receive(self.by_fd[fd], now)
                    continue
                data = os.read(control, 4096)
                if not data:
                    return
                pending += data
                while b"\n" in pending:
                    line, pending = pending.split(b"\n", 1)
                    answer = self.command(line.decode(errors="replace"))
                    if answer:
                        print(answer, flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--host", action="append", default=[], metavar="NAME=NAMESPACE=ADDRESS",
                        help="a host at start (more come with the line 'host NAME NAMESPACE ADDRESS')")
    parser.add_argument("--prefix", default=f"aex{os.getpid()}", help="the TUN devices' names begin with it")
    parser.add_argument("--delay", type=float, default=0.0, metavar="MS")
    parser.add_argument("--jitter", type=float, default=0.0, metavar="MS")
    parser.add_argument("--duplicate", type=float, default=0.0, metavar="PERCENT")
    parser.add_argument("--in-order", action="store_true", help="no reordering (reorder 0)")
    parser.add_argument("--seed", type=int)
    args = parser.parse_args(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    relay = Relay(Faults(args.delay, args.jitter, not args.in_order, args.duplicate), args.prefix, args.seed)
    for spec in args.host:
        relay.add(*spec.split("="))
    print("ready", flush=True)
    relay.run(sys.stdin.fileno())
    return 0


if __name__ == "__main__":
    sys.exit(main())
