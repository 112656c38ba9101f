"""A fleet over several hosts of the testbed, as docs/fleet-testbed.md deploys it: credentials made once, a router on
each drone host (each after the first linked to the first: ``fleet --router --listen ... --connect ...``), drones
joining their own host's router (``run --fleet``), the operator on a host of its own reaching the fleet through the
first host's router (``ctl --fleet``). Used by tests/fleet/test_fleet_network.py and bench/fleet_network.py."""

from __future__ import annotations

import json
import os
import re
import shlex
import signal
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from processes import HOVER, TOKEN, Output, stop
from testbed import Host, Testbed

PORT = 7447  # each host has its own network stack: the same port on every one
HEARD = re.compile(r"fleet_drone_heard: (.+?)(?: and (\d+) more)? (?:is|are) in the fleet")


@dataclass
class Command:
    """One ``ctl --fleet`` by the operator: its process's end, each drone's answer (``--json``)."""

    done: subprocess.CompletedProcess
    answers: dict[str, dict]

    @property
    def reached(self) -> dict[str, float]:
        """Seconds from the command's sending to its arrival, for each drone it reached."""
        return {d: a["reached"] for d, a in self.answers.items() if isinstance(a.get("reached"), (int, float))}


@dataclass
class FleetOfHosts:
    """Fleet ``search`` of ``per_host`` drones on each of ``drone_hosts`` hosts of ``bed``, the operator on one more
    host; :meth:`start` starts its routers and drones."""

    bed: Testbed
    folder: Path
    drone_hosts: int = 3
    per_host: int = 2
    mission: str = HOVER
    paths: int = 0  # routers the operator's commands go through at once: 0, every one; 1, the first only
    processes: list[subprocess.Popen] = field(default_factory=list)
    commands: list[Command] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.hosts = [self.bed.host(f"h{n}") for n in range(1, self.drone_hosts + 1)]
        self.operator = self.bed.host("op")
        self.names = [f"d{n}" for n in range(1, self.drone_hosts * self.per_host + 1)]
        self.host_of = {name: self.hosts[n // self.per_host] for n, name in enumerate(self.names)}
        self.env = {**os.environ, "AEROEXEC_FLEET_TOKEN": TOKEN}
        (self.folder / "hover.py").write_text(self.mission)
        roster = "".join(f"  - {{name: {name}}}\n" for name in self.names)
        (self.folder / "search.yaml").write_text(f"fleet: search\ncredentials: creds\nshare: [object]\n"
                                                 f"drones:\n{roster}")
        listen = [word for host in self.hosts for word in ("--listen", self.endpoint(host))]
        made = self.hosts[0].run("aeroexec", "fleet", "search.yaml", "--make-credentials", "creds", *listen,
                                 cwd=self.folder, env=self.env)
        assert made.returncode == 0, made.stdout + made.stderr
        self.routers: dict[str, Output] = {}
        self.drones: dict[str, Output] = {}

    @staticmethod
    def endpoint(host: Host) -> str:
        return f"tls/{host.address}:{PORT}"

    def connect_words(self) -> list[str]:
        """``--connect`` for each router the operator sends its commands through (``paths``: 0, every one)."""
        return [word for host in self.hosts[:self.paths or None] for word in ("--connect", self.endpoint(host))]

    def on(self, host: Host, *words: str) -> Output:
        process = host.popen("aeroexec", *words, cwd=self.folder, env=self.env)
        self.processes.append(process)
        return Output(process)

    def router(self, host: Host, timeout: float) -> Output:
        """The fleet's router on ``host`` (linked to the first host's), once it listens."""
        linked = ("--connect", self.endpoint(self.hosts[0])) if host is not self.hosts[0] else ()
        out = self.on(host, "fleet", "search.yaml", "--router", "--listen", self.endpoint(host), *linked, "--output",
                      f"router-{host.name}")
        out.wait(lambda lines: seen(lines, "listening on"), f"the router on {host.name}", timeout)
        self.routers[host.name] = out
        return out

    def start(self, timeout: float, loss: int = 0) -> None:
        """Every router, then ``loss`` % of the packets reaching each host dropped, then every drone, once each
        flies and has heard every other."""
        for host in self.hosts:
            self.router(host, timeout)
        for host in self.bed.hosts:
            self.bed.lose(host, loss)
        for name in self.names:
            host = self.host_of[name]
            self.drones[name] = self.on(host, "run", "hover.py", "--fleet", "search", "--name", name, "--credentials",
                                        "creds", "--connect", self.endpoint(host), "--share", "object", "--plain",
                                        "--output", name)
        mates = len(self.names) - 1
        for name, drone in self.drones.items():
            drone.wait(lambda lines: seen(lines, "drone_takeoff_complete") and mates_heard(lines) >= mates,
                       f"{name} flying, hearing every other drone", timeout)

    def ctl(self, *words: str) -> Command:
        """``aeroexec ctl --fleet search WORDS --json`` by the operator on its own host, through every router at
        once (each a path; each drone's first answer counts); the roster from the first router's fleet.json."""
        paths = self.connect_words()
        done = self.operator.run("aeroexec", "ctl", "--fleet", "search", *words, "--json", "--credentials", "creds",
                                 *paths, "--run", f"router-{self.hosts[0].name}", cwd=self.folder, env=self.env)
        try:
            answers = json.loads(done.stdout) if done.stdout.strip() else {}
        except ValueError:
            answers = {}
        command = Command(done, answers)
        self.commands.append(command)
        return command

    def console(self, timeout: float) -> Console:
        """``aeroexec ctl --fleet search --stdin --json`` kept open by the operator on its own host (a ground
        station's console: its links to every router opened once); :meth:`Console.ctl` sends it a command."""
        paths = self.connect_words()
        process = subprocess.Popen(self.operator.command("aeroexec", "ctl", "--fleet", "search", "--stdin", "--json",
                                                         "--credentials", "creds", *paths, "--run",
                                                         f"router-{self.hosts[0].name}"),
                                   cwd=self.folder, env=self.env, text=True, stdin=subprocess.PIPE,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        self.processes.append(process)
        return Console(self, Output(process), timeout)

    def kill_router(self, host: Host) -> None:
        process = self.routers.pop(host.name).process
        process.send_signal(signal.SIGKILL)  # no goodbye
        process.wait(30)

    def ended(self, timeout: float) -> None:
        """Every drone's process ended, its output read to the end."""
        for drone in self.drones.values():
            drone.process.wait(timeout)
            drone.wait(lambda lines: lines[-1:] == [""], "the end of a drone's output", timeout)

    def close(self) -> None:
        stop(*self.processes)


@dataclass
class Console:
    """The operator's ``ctl --stdin`` process: a command a line in, its answers a JSON line out."""

    fleet: FleetOfHosts
    out: Output
    timeout: float

    def ctl(self, *words: str) -> Command:
        """``words`` as one line (``COMMAND [ARGUMENT] [--drone D]``), its answers once they are printed."""
        mark = len(self.out.lines)
        self.out.process.stdin.write(" ".join(shlex.quote(word) for word in words) + "\n")
        self.out.process.stdin.flush()
        lines = self.out.wait(lambda lines: any(line.startswith("{") for line in lines[mark:]), f"ctl {words}",
                              self.timeout)
        said = lines[mark:]
        answer = next(line for line in said if line.startswith("{"))
        answers = json.loads(answer)
        done = subprocess.CompletedProcess(["ctl", *words], 0 if all(a.get("ok") for a in answers.values()) else 1,
                                           answer, "".join(line for line in said if line is not answer))
        command = Command(done, answers)
        self.fleet.commands.append(command)
        return command

    def close(self) -> int:
        """Standard input closed: the console closes its links and ends; its exit status."""
        self.out.process.stdin.close()
        return self.out.process.wait(self.timeout)


def seen(lines: list[str], text: str, after: int = 0) -> bool:
    return any(text in line for line in lines[after:])


def reported_silent(lines: list[str], mate: str, after: int) -> bool:
    """Whether a drone's event lines say ``mate`` is silent since line ``after``: said after it, or said before it and
    not heard again since (under loss a link may stall for seconds: a mate silent already when a fault comes is not
    said silent a second time)."""
    if seen(lines, f"fleet_drone_silent: {mate}:", after):
        return True
    mentioned = re.compile(rf"\b{re.escape(mate)}\b")
    for line in reversed(lines[:after]):
        if f"fleet_drone_silent: {mate}:" in line:
            return True
        if "fleet_drone_heard:" in line and mentioned.search(line.split("fleet_drone_heard:", 1)[1]):
            return False
    return False


def mates_heard(lines: list[str]) -> int:
    """How many other drones a drone said it heard (``fleet_drone_heard: d2, d3 and 2 more are in the fleet``)."""
    count = 0
    for line in lines:
        found = HEARD.search(line)
        if found:
            count += len(found.group(1).split(", ")) + int(found.group(2) or 0)
    return count


def when(out: Output, text: str, after: int = 0) -> float | None:
    """time.monotonic() of the first line of ``out`` from line ``after`` on that holds ``text``, or None."""
    return next((out.times[n] for n in range(after, len(out.times)) if text in out.lines[n]), None)


def percentile(values: list[float], q: float) -> float:
    """The ``q``-th percentile (nearest rank) of ``values``."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, round(q / 100 * len(ordered) + 0.5) - 1))]


def since(start: float) -> float:
    return time.monotonic() - start
