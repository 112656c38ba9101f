"""The fleet over several machines of docs/fleets.md, on hosts of their own (network namespaces on one switch,
:mod:`testbed`): a router on each host, the second linked to the first (``--router --connect``), a drone on each
host joined through its own host's router (``run --fleet``), the operator (``ctl --fleet``) on a host: under packet
loss, with a host cut off and healed, with a router killed and started again."""

import os
import signal
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from processes import HOVER, TOKEN, Output, stop
from testbed import Host, Latency, Testbed

PORT = 7447  # each host has its own network stack: the README's port is free on every one


@pytest.fixture
def testbed():
    bed = Testbed()
    yield bed
    bed.close()


@dataclass
class TwoHosts:
    """Fleet ``search`` on hosts a and b of ``bed``: :meth:`start` its routers and drones (d1 on a, d2 on b)."""

    bed: Testbed
    folder: Path
    processes: list[subprocess.Popen] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.a, self.b = self.bed.host("a"), self.bed.host("b")
        self.at = {self.a.namespace: f"tls/{self.a.address}:{PORT}", self.b.namespace: f"tls/{self.b.address}:{PORT}"}
        self.env = {**os.environ, "AEROEXEC_FLEET_TOKEN": TOKEN}  # the README's operator line sets it too
        (self.folder / "hover.py").write_text(HOVER)
        (self.folder / "search.yaml").write_text("fleet: search\ncredentials: creds\ndrones:\n  - {name: d1}\n"
                                                 "  - {name: d2}\n")
        made = self.a.run("aeroexec", "fleet", "search.yaml", "--make-credentials", "creds", "--listen",
                          self.endpoint(self.a), "--listen", self.endpoint(self.b), cwd=self.folder, env=self.env)
        assert made.returncode == 0, made.stdout + made.stderr

    def endpoint(self, host: Host) -> str:
        return self.at[host.namespace]

    def run(self, host: Host, *words: str) -> Output:
        process = host.popen("aeroexec", *words, cwd=self.folder, env=self.env)
        self.processes.append(process)
        return Output(process)

    def router(self, host: Host) -> Output:
        """The fleet's router on ``host`` (b's linked to a's), once it listens."""
        linked = ("--connect", self.endpoint(self.a)) if host is self.b else ()
        out = self.run(host, "fleet", "search.yaml", "--router", "--listen", self.endpoint(host), *linked,
                       "--output", f"router-{host.namespace}")
        out.wait(lambda lines: seen(lines, "listening on"), f"the router on {host.namespace}", 60)
        return out

    def start(self) -> dict[str, Output]:
        """Both routers and both drones, once each drone flies and hears the other."""
        self.routers = {"a": self.router(self.a), "b": self.router(self.b)}
        self.drones = {name: self.run(host, "run", "hover.py", "--fleet", "search", "--name", name, "--credentials",
                                      "creds", "--connect", self.endpoint(host), "--plain", "--output", name)
                       for name, host in (("d1", self.a), ("d2", self.b))}
        for name, other in (("d1", "d2"), ("d2", "d1")):
            self.drones[name].wait(lambda lines, other=other: seen(lines, f"fleet_drone_heard: {other} is in the fleet")
                                   and seen(lines, "drone_takeoff_complete"), f"{name} flying, hearing {other}", 120)
        return self.drones

    def ctl(self, host: Host, command: str) -> subprocess.CompletedProcess:
        """The operator on ``host``, through its router."""
        return host.run("aeroexec", "ctl", "--fleet", "search", command, "--credentials", "creds", "--connect",
                        self.endpoint(host), cwd=self.folder, env=self.env)

    def abort_both(self, host: Host) -> None:
        """``ctl --fleet search abort`` on ``host`` reaches both drones, which land and end aborted."""
        aborted = self.ctl(host, "abort")
        assert aborted.returncode == 0, aborted.stdout + aborted.stderr
        assert "d1: mission aborted" in aborted.stdout and "d2: mission aborted" in aborted.stdout, aborted.stdout
        for out in self.drones.values():
            out.process.wait(120)
            out.wait(lambda lines: lines[-1:] == [""], "the end of a drone's output", 30)
        for out in self.drones.values():
            assert out.process.returncode != 0, out.text[-3000:]  # aborted: not completed
            assert "hover.py: aborted" in out.text and "drone_disarmed" in out.text, out.text[-3000:]

    def close(self) -> None:
        stop(*self.processes)


def seen(lines: list[str], text: str, after: int = 0) -> bool:
    return any(text in line for line in lines[after:])


def assert_flew_on(drone: Output, since: int) -> None:
    """From its line ``since`` to the operator's abort the drone flew on: nothing landed it."""
    commanded = next(n for n, line in enumerate(drone.lines) if "aborted by the operator" in line)
    assert since < commanded
    assert not any("LAND" in line or "landed" in line for line in drone.lines[since:commanded]), drone.text[-3000:]


@pytest.fixture
def fleet(testbed, tmp_path):
    hosts = TwoHosts(testbed, tmp_path)
    yield hosts
    hosts.close()


def test_two_drones_on_two_hosts_fly_through_their_routers_and_the_operator_aborts_both_under_loss(fleet):
    fleet.start()
    fleet.bed.lose(fleet.a, 20)
    fleet.bed.lose(fleet.b, 20)
    status = fleet.ctl(fleet.a, "status")
    assert status.returncode == 0, status.stdout + status.stderr
    assert "d1: running" in status.stdout and "d2: running" in status.stdout, status.stdout
    fleet.abort_both(fleet.a)


def test_a_host_cut_off_keeps_flying_is_named_by_the_operator_and_is_heard_again_and_commanded_after_the_heal(
        fleet):
    """Host b (its router and d2) is cut off the network: d1 reports d2 silent, the operator on host a hears d1 and
    names d2 as not answering, the operator on host b reaches d2, which flies on; after the heal the routers link
    again without anyone's help, d1 hears d2 again, and one ctl abort reaches both."""
    d1, d2 = fleet.start().values()
    fleet.bed.cut(fleet.b)
    d1.wait(lambda lines: seen(lines, "fleet_drone_silent: d2"), "d2 silent for d1", 120)
    cut_off = len(d2.lines)
    status = fleet.ctl(fleet.a, "status")
    assert status.returncode == 1, status.stdout + status.stderr
    assert "d1: running" in status.stdout and "d2: did not answer" in status.stderr, status.stdout + status.stderr
    there = fleet.ctl(fleet.b, "status")  # the operator on the cut-off host still reaches its drone, in the air
    assert "d2: running" in there.stdout and "in_air" in there.stdout, there.stdout + there.stderr
    assert "d1: did not answer" in there.stderr, there.stderr
    fleet.bed.heal(fleet.b)
    healed = len(d1.lines)
    d1.wait(lambda lines: seen(lines, "d2 is heard again", healed), "d2 heard again after the heal", 120)
    fleet.abort_both(fleet.a)
    assert_flew_on(d2, cut_off)


def test_a_router_killed_and_started_again_is_rejoined_by_its_drone_and_the_other_router_without_help(fleet):
    d1, d2 = fleet.start().values()
    router = fleet.routers["b"].process
    router.send_signal(signal.SIGKILL)  # no goodbye
    router.wait(30)
    d1.wait(lambda lines: seen(lines, "fleet_drone_silent: d2"), "d2 silent for d1", 120)
    killed = len(d2.lines)
    fleet.routers["b"] = fleet.router(fleet.b)  # the same command again, nothing else
    d1.wait(lambda lines: seen(lines, "d2 is heard again", killed), "d2 heard again through the new router", 120)
    d2.wait(lambda lines: seen(lines, "d1 is heard again", killed), "d1 heard again by d2", 120)
    fleet.abort_both(fleet.a)
    assert_flew_on(d2, killed)


ECHO = """import socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("0.0.0.0", 9000))
print("ready", flush=True)
while True:
    data, sender = s.recvfrom(100)
    print(data.decode(), flush=True)
"""
SEND = """import socket, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
for n in range(int(sys.argv[3]), int(sys.argv[3]) + int(sys.argv[2])):
    s.sendto(str(n).encode(), (sys.argv[1], 9000))
    time.sleep(0.002)
s.sendto(b"end", (sys.argv[1], 9000))
"""
ROUND_TRIP = """import socket, sys, time
started = time.monotonic()
with socket.create_connection((sys.argv[1], 9001), timeout=30) as s:
    s.sendall(b"x")
    s.recv(1)
print(time.monotonic() - started)
"""
SERVE = """import socket
s = socket.socket()
s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
s.bind(("0.0.0.0", 9001))
s.listen()
print("ready", flush=True)
c, _ = s.accept()
c.sendall(c.recv(1))
"""


def test_the_relay_holds_every_packet_reorders_duplicates_and_cuts_a_host(tmp_path):
    """Hosts on the delaying relay: a TCP connection and one round trip (3 packets one way, 2 back at the least)
    take at least 5 x 50 ms (each packet held 200 +- 150 ms: five drawn short together made 0.75 s in a CI run);
    of 300 datagrams sent 2 ms apart with 150 ms of jitter and 20 % duplicated, some arrive twice and some before
    one sent earlier; a host cut off receives nothing until it is healed."""
    with Testbed(Latency(200, 150, reorder=True, duplicate=20)) as bed:
        a, b = bed.host("a"), bed.host("b")
        server = subprocess.Popen(b.command(sys.executable, "-c", SERVE), stdout=subprocess.PIPE, text=True)
        echo = subprocess.Popen(b.command(sys.executable, "-c", ECHO), stdout=subprocess.PIPE, text=True)
        try:
            assert server.stdout.readline().strip() == "ready" and echo.stdout.readline().strip() == "ready"
            trip = a.run(sys.executable, "-c", ROUND_TRIP, b.address, cwd=tmp_path)
            assert trip.returncode == 0, trip.stderr
            assert float(trip.stdout) >= 5 * 0.050, trip.stdout  # the least the relay holds five packets
            sent = a.run(sys.executable, "-c", SEND, b.address, "300", "0", cwd=tmp_path)
            assert sent.returncode == 0, sent.stderr
            got = Output(echo)
            got.wait(lambda lines: seen(lines, "end"), "the datagrams", 60)
            numbers = [int(line) for line in got.lines if line.strip().isdigit()]
            assert len(numbers) > len(set(numbers)), "no datagram came twice"
            assert any(later < earlier for earlier, later in zip(numbers, numbers[1:], strict=False)), \
                "none overtook another"
            bed.cut(b)
            a.run(sys.executable, "-c", SEND, b.address, "20", "1000", cwd=tmp_path)  # 1000 to 1019: lost
            bed.heal(b)
            a.run(sys.executable, "-c", SEND, b.address, "1", "2000", cwd=tmp_path)
            got.wait(lambda lines: seen(lines, "2000"), "the datagram after the heal", 60)
            assert not any(1000 <= int(line) < 1020 for line in got.lines if line.strip().isdigit()), got.text
        finally:
            stop(server, echo)
    assert not any(n.startswith(bed.prefix) for n in subprocess.run(
        ["ip", "netns", "list"], capture_output=True, text=True).stdout.split()), "a namespace was left"
