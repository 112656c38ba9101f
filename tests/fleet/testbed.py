"""A fleet testbed of hosts on one machine: each host a Linux network namespace of its own, joined to the others by
a veth pair to a bridge in a switch namespace, as machines on one network (``10.77.0.0/24``), with faults an
operator meets in the field: packets dropped at random (nftables ``numgen random mod 100 < P drop`` on a host's
way in) and a host cut off (its switch port ``ip link set down``) and healed.

With ``Testbed(Latency(200, 50))`` the hosts are joined by the delaying relay instead (:mod:`relay`, a process of
its own): each host's ``eth0`` is a TUN device, every packet is held 200 ± 50 ms on its way to the other host
(reordered, duplicated as :class:`Latency` says), and a host cut off is one the relay drops every packet from and
to; the loss is nftables' as on the switch.

It addresses only the namespaces it creates (named after this process, ``aex<pid>-<host>``) and deletes them on
:meth:`Testbed.close`. It needs root (CI runs as root), ``ip`` (iproute2) and ``nft`` (nftables); without them
:class:`Testbed` says which is missing. The kernel of the project's machine has no ``netem``, so latency is not
made here (a delaying relay between namespaces would be the way).

    bed = Testbed()
    a, b = bed.host("a"), bed.host("b")
    process = a.popen("aeroexec", "fleet", "search.yaml", "--router", "--listen", f"tls/{a.address}:7447")
    bed.lose(b, 20)   # 20 % of what reaches b is dropped
    bed.cut(b); bed.heal(b)
    bed.close()

    with Testbed(Latency(200, 50, duplicate=1)) as bed:   # the same, each packet 200 +- 50 ms late
        ...
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

RELAY = Path(__file__).with_name("relay.py")

NETWORK = "10.77.0"  # /24: host n has NETWORK.n
SWITCH = "sw"
BRIDGE = "br0"
NIC = "eth0"  # each host's side of its link


class TestbedError(RuntimeError):
    """The testbed cannot be made on this machine; the text says why."""


def _run(*command: str, stdin: str | None = None) -> None:
    done = subprocess.run(command, input=stdin, capture_output=True, text=True, timeout=60)
    if done.returncode != 0:
        raise TestbedError(f"{' '.join(command)}: {done.stderr.strip() or done.stdout.strip()}")


@dataclass
class Host:
    """One host of the testbed: its namespace, its address on the network, its port on the switch."""

    namespace: str
    address: str
    port: str
    name: str = ""

    def command(self, *words: str) -> list[str]:
        """``words`` run in this host's namespace (``aeroexec ...`` as this checkout's Python runs it)."""
        if words and words[0] == "aeroexec":
            words = (sys.executable, "-m", "aeroexec.cli.main", *words[1:])
        return ["ip", "netns", "exec", self.namespace, *words]

    def popen(self, *words: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.Popen:
        """A process on this host, its output (stdout and stderr) as text lines on ``stdout``."""
        return subprocess.Popen(self.command(*words), cwd=cwd, env=env, text=True, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT)

    def run(self, *words: str, cwd: Path, env: dict[str, str] | None = None,
            timeout: float = 120) -> subprocess.CompletedProcess:
        return subprocess.run(self.command(*words), cwd=cwd, env=env, capture_output=True, text=True,
                              timeout=timeout)


@dataclass
class Latency:
    """The relay's faults: each packet ``delay`` ± ``jitter`` ms late (uniform, drawn for each packet), overtaking
    others when ``reorder``, ``duplicate`` % of them sent twice."""

    delay: float = 200.0
    jitter: float = 50.0
    reorder: bool = True
    duplicate: float = 0.0


@dataclass
class Testbed:
    """Hosts on one switch (or, with ``latency``, on the delaying relay); :meth:`close` deletes every namespace it
    made and ends the relay."""

    __test__ = False  # a fixture's helper, not a test class
    latency: Latency | None = None
    #: Each host's ``net.ipv4.tcp_retries2`` (docs/fleet-testbed.md sets it on the routers' machines): a TCP link
    #: whose other end is gone is dropped after about 13 s of retransmissions instead of about 15 minutes, so a
    #: router relinks within seconds of a heal (the kernel's 15: 18 to 70 s). None: the kernel's.
    tcp_retries2: int | None = 5
    prefix: str = field(default_factory=lambda: f"aex{os.getpid()}")
    hosts: list[Host] = field(default_factory=list)
    _made: list[str] = field(default_factory=list)
    _relay: subprocess.Popen | None = None

    def __post_init__(self) -> None:
        missing = [tool for tool in ("ip", "nft") if shutil.which(tool) is None]
        if missing:
            raise TestbedError(f"the fleet testbed needs {' and '.join(missing)} (Debian: iproute2, nftables)")
        if os.geteuid() != 0:
            raise TestbedError("the fleet testbed makes network namespaces: run it as root (CI does)")
        try:
            if self.latency is not None:
                self._start_relay(self.latency)
                return
            self.switch = self._namespace(SWITCH)
            _run("ip", "-n", self.switch, "link", "add", BRIDGE, "type", "bridge")
            _run("ip", "-n", self.switch, "link", "set", BRIDGE, "up")
        except BaseException:
            self.close()
            raise

    def __enter__(self) -> Testbed:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    def _start_relay(self, latency: Latency) -> None:
        self._relay = subprocess.Popen(
            [sys.executable, str(RELAY), "--prefix", self.prefix, "--delay", str(latency.delay), "--jitter",
             str(latency.jitter), "--duplicate", str(latency.duplicate), *(() if latency.reorder else ("--in-order",))],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        if self._relay.stdout.readline().strip() != "ready":
            raise TestbedError(f"the delaying relay did not start (exit {self._relay.wait(30)})")

    def relay(self, line: str) -> str:
        """A line to the relay (:mod:`relay` lists them), its answer; TestbedError if it refused."""
        if self._relay is None:
            raise TestbedError("this testbed has no relay: make it with Testbed(Latency(...))")
        self._relay.stdin.write(line + "\n")
        self._relay.stdin.flush()
        answer = self._relay.stdout.readline().strip()
        if answer.startswith("error") or not answer:
            raise TestbedError(f"the relay refused {line!r}: {answer or 'it ended'}")
        return answer

    def carried(self) -> dict[str, list[int]]:
        """What the relay carried for each host: packets in, bytes in, packets out, bytes out."""
        return json.loads(self.relay("stats").removeprefix("stats "))

    def _namespace(self, name: str) -> str:
        namespace = f"{self.prefix}-{name}"
        _run("ip", "netns", "add", namespace)
        self._made.append(namespace)
        _run("ip", "-n", namespace, "link", "set", "lo", "up")
        return namespace

    def host(self, name: str) -> Host:
        """A new host on the switch, at the network's next address."""
        namespace = self._namespace(name)
        if self.tcp_retries2 is not None:
            _run("ip", "netns", "exec", namespace, "sysctl", "-q", "-w", f"net.ipv4.tcp_retries2={self.tcp_retries2}")
        n = len(self.hosts) + 1
        host = Host(namespace, f"{NETWORK}.{n}", f"p{n}", name)
        self.hosts.append(host)
        if self._relay is not None:
            self.relay(f"host {name} {namespace} {host.address}")
            return host
        _run("ip", "-n", namespace, "link", "add", NIC, "type", "veth", "peer", "name", host.port, "netns",
             self.switch)
        _run("ip", "-n", namespace, "addr", "add", f"{host.address}/24", "dev", NIC)
        _run("ip", "-n", namespace, "link", "set", NIC, "up")
        _run("ip", "-n", self.switch, "link", "set", host.port, "master", BRIDGE)
        _run("ip", "-n", self.switch, "link", "set", host.port, "up")
        return host

    def sent(self, host: Host) -> tuple[int, int]:
        """Packets and bytes ``host`` has sent on the network so far (its ``eth0``)."""
        done = subprocess.run(["ip", "netns", "exec", host.namespace, "cat", "/proc/net/dev"], capture_output=True,
                              text=True, timeout=60)
        for line in done.stdout.splitlines():
            name, _, numbers = line.partition(":")
            if name.strip() == NIC:
                fields = numbers.split()
                return int(fields[9]), int(fields[8])
        raise TestbedError(f"{host.namespace} has no {NIC}: {done.stderr.strip()}")

    def lose(self, host: Host, percent: int) -> None:
        """Drop ``percent`` % of the packets reaching ``host`` from the network, at random (0: none)."""
        rules = "table inet testbed\ndelete table inet testbed\ntable inet testbed {\n" \
                "  chain input {\n    type filter hook input priority 0; policy accept;\n" \
                + (f"    iifname \"{NIC}\" numgen random mod 100 < {int(percent)} drop\n" if percent else "") \
                + "  }\n}\n"
        _run("ip", "netns", "exec", host.namespace, "nft", "-f", "-", stdin=rules)

    def cut(self, host: Host) -> None:
        """Cut ``host`` off the network (its switch port down, or the relay drops its packets): a partition."""
        if self._relay is not None:
            self.relay(f"cut {host.name}")
        else:
            _run("ip", "-n", self.switch, "link", "set", host.port, "down")

    def heal(self, host: Host) -> None:
        if self._relay is not None:
            self.relay(f"heal {host.name}")
        else:
            _run("ip", "-n", self.switch, "link", "set", host.port, "up")

    def close(self) -> None:
        """End the relay, delete the namespaces this testbed made (the processes in them are the caller's to end
        first)."""
        if self._relay is not None:
            relay, self._relay = self._relay, None
            relay.stdin.close()
            try:
                relay.wait(30)
            except subprocess.TimeoutExpired:
                relay.kill()
                relay.wait(30)
            relay.stdout.close()
        for namespace in reversed(self._made):
            subprocess.run(["ip", "netns", "del", namespace], capture_output=True, timeout=60)
        self._made.clear()
