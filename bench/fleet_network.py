"""The fleet of docs/fleet-testbed.md under each fault of the testbed, measured: 6 drones on 3 hosts (a router each,
linked to the first host's), the operator on a fourth host (tests/fleet/testbed.py and hosts.py; root only).

For each fault a fresh testbed: the fleet started, ``--commands`` operator commands (``ctl --fleet search status``)
sent while the fault holds, then (for a partition or a router restart) the heal. Printed per fault:

- command latency p50/p99: seconds from the operator's sending of a command to its arrival at each drone it
  reached (each answer's ``reached``), with the commands that reached every drone;
- converge: seconds from the heal (partition) or from the router's start (restart) until every drone said it
  hears every other again, and the drones cut off believe what was said meanwhile (partition);
- packets and bytes per drone per second between hosts: what the drone hosts sent on the network over the window
  (their drones' and router's messages, with TCP's acknowledgements and retransmissions) over the drones' count;
- CPU per drone-second: the drone processes' CPU time over the window over (drones x window), and the routers'.

    sudo python bench/fleet_network.py                      # every fault, about 10 minutes
    sudo python bench/fleet_network.py --faults loss latency+loss --commands 20
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests" / "fleet"), str(ROOT / "tests")]

from hosts import FleetOfHosts, percentile, seen, when  # noqa: E402
from testbed import Latency, Testbed  # noqa: E402

FOUND = "object(marker_9, aruco)"


@dataclass
class Fault:
    """A network (latency or not, loss) and what happens in it (``event``: none, partition, restart)."""

    name: str
    latency: Latency | None
    loss: int
    event: str = "none"


FAULTS = {
    "none": Fault("none", None, 0),
    "loss": Fault("loss 20 %", None, 20),
    "latency": Fault("latency 200±50 ms", Latency(200, 50, duplicate=1), 0),
    "latency+loss": Fault("latency 200±50 ms, loss 20 %", Latency(200, 50, duplicate=1), 20),
    "half-latency+loss": Fault("latency 100±25 ms, loss 20 %", Latency(100, 25, duplicate=1), 20),
    "partition": Fault("latency+loss, host 3 cut 30 s", Latency(200, 50, duplicate=1), 20, "partition"),
    "restart": Fault("latency+loss, router 2 killed, restarted", Latency(200, 50, duplicate=1), 20, "restart"),
}


def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` and its waited-for children (0 once it is gone)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return sum(int(v) for v in fields[11:15]) / os.sysconf("SC_CLK_TCK")


def measure(fault: Fault, commands: int, cut_for: float, timeout: float, paths: int = 0,
            operator: str = "console") -> dict[str, float | str]:
    with Testbed(fault.latency) as bed, tempfile.TemporaryDirectory(prefix="fleet_network") as folder:
        fleet = FleetOfHosts(bed, Path(folder), paths=paths)
        try:
            fleet.start(timeout, loss=fault.loss)
            drones = [out.process.pid for out in fleet.drones.values()]
            routers = [out.process.pid for out in fleet.routers.values()]
            carried = {h.name: bed.sent(h) for h in fleet.hosts}
            cpu = [sum(cpu_seconds(p) for p in drones), sum(cpu_seconds(p) for p in routers)]
            start = time.monotonic()
            converge = float("nan")
            if fault.event == "partition":
                converge = partition(fleet, cut_for, timeout)
            elif fault.event == "restart":
                converge = restart(fleet, timeout)
            reach, whole = [], 0
            console = fleet.console(timeout) if operator == "console" else None
            for _ in range(commands):
                command = console.ctl("status") if console is not None else fleet.ctl("status")
                reach += command.reached.values()
                whole += len(command.reached) == len(fleet.names)
            window = time.monotonic() - start
            cpu = [sum(cpu_seconds(p) for p in drones) - cpu[0],
                   sum(cpu_seconds(out.process.pid) for out in fleet.routers.values()) - cpu[1]]
            after = {h.name: bed.sent(h) for h in fleet.hosts}
        finally:
            fleet.close()
    n = len(fleet.names)
    drone_hosts = [h.name for h in fleet.hosts]
    packets = sum(after[h][0] - carried[h][0] for h in drone_hosts)
    sent = sum(after[h][1] - carried[h][1] for h in drone_hosts)
    return {"fault": fault.name, "p50": percentile(reach, 50) if reach else float("nan"),
            "p99": percentile(reach, 99) if reach else float("nan"), "whole": f"{whole}/{commands}",
            "converge": converge, "packets": packets / n / window, "bytes": sent / n / window,
            "cpu": cpu[0] / (n * window), "router_cpu": cpu[1] / (len(drone_hosts) * window)}


def partition(fleet: FleetOfHosts, cut_for: float, timeout: float) -> float:
    """Host 3 cut off for ``cut_for`` s, d1 saying FOUND meanwhile; seconds from the heal to convergence."""
    h3, d = fleet.hosts[2], fleet.drones
    there = [name for name in fleet.names if fleet.host_of[name] is h3]
    here = [name for name in fleet.names if name not in there]
    cut = time.monotonic()
    fleet.bed.cut(h3)
    marks = {name: len(out.lines) for name, out in d.items()}
    for name in here:
        for mate in there:
            d[name].wait(lambda lines, m=mate, n=name: seen(lines, f"fleet_drone_silent: {m}", marks[n]),
                         f"{mate} silent for {name}", timeout)
    fleet.ctl("add", FOUND, "--drone", here[0])
    time.sleep(max(0.0, cut_for - (time.monotonic() - cut)))
    healed = {name: len(out.lines) for name, out in d.items()}
    heal = time.monotonic()
    fleet.bed.heal(h3)
    expected = {name: [f"{m} is heard again" for m in (there if name in here else here)] for name in fleet.names}
    for name in there:
        expected[name].append(f"fleet_belief: from {here[0]}: {FOUND}")
    return settled(fleet, expected, healed, heal, timeout)


def restart(fleet: FleetOfHosts, timeout: float) -> float:
    """Host 2's router killed and started again once the others say its drones are silent; seconds from its start
    to every drone hearing every other again."""
    h2, d = fleet.hosts[1], fleet.drones
    there = [name for name in fleet.names if fleet.host_of[name] is h2]
    here = [name for name in fleet.names if name not in there]
    marks = {name: len(out.lines) for name, out in d.items()}
    fleet.kill_router(h2)
    for mate in there:
        d[here[0]].wait(lambda lines, m=mate: seen(lines, f"fleet_drone_silent: {m}", marks[here[0]]),
                        f"{mate} silent", timeout)
    marks = {name: len(out.lines) for name, out in d.items()}
    started = time.monotonic()
    fleet.router(h2, timeout)
    expected = {name: [f"{m} is heard again" for m in (there if name in here else here)] for name in fleet.names}
    return settled(fleet, expected, marks, started, timeout)


def settled(fleet: FleetOfHosts, expected: dict[str, list[str]], marks: dict[str, int], since: float,
            timeout: float) -> float:
    d = fleet.drones
    for name, texts in expected.items():
        d[name].wait(lambda lines, t=texts, n=name: all(seen(lines, x, marks[n]) for x in t), f"{name} settled",
                     timeout)
    return max(when(d[name], text, marks[name]) for name, texts in expected.items() for text in texts) - since


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--faults", nargs="+", choices=list(FAULTS), default=list(FAULTS))
    parser.add_argument("--commands", type=int, default=10, help="operator commands per fault (default 10)")
    parser.add_argument("--cut", type=float, default=30.0, help="seconds host 3 is cut off (default 30)")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds any one wait may take")
    parser.add_argument("--operator", nargs="+", choices=("console", "ctl"), default=["console"],
                        help="how the operator sends its commands: console, one ctl --stdin whose links to the "
                             "routers stay open (the default); ctl, a one-shot ctl per command (its links opened "
                             "for each); several: each fault measured with each")
    parser.add_argument("--paths", type=int, nargs="+", default=[0], metavar="K",
                        help="routers each command goes through at once: 0 every one (the default, as the docs "
                             "deploy it), 1 the first only; several values: each fault measured with each")
    args = parser.parse_args()
    if os.geteuid() != 0:
        print("bench/fleet_network.py makes network namespaces: run it as root", file=sys.stderr)
        return 2
    print(f"{'fault':<42} {'operator':>8} {'paths':>5} {'p50 s':>6} {'p99 s':>6} {'whole':>6} {'converge s':>10} "
          f"{'pkt/drone/s':>11} {'B/drone/s':>9} {'CPU/drone-s':>11} {'router CPU':>10}")
    for name, operator, paths in ((n, o, p) for n in args.faults for o in args.operator for p in args.paths):
        r = measure(FAULTS[name], args.commands, args.cut, args.timeout, paths, operator)
        print(f"{r['fault']:<42} {operator:>8} {paths or 'all':>5} {r['p50']:>6.2f} {r['p99']:>6.2f} {r['whole']:>6} "
              f"{r['converge']:>10.1f} {r['packets']:>11.1f} {r['bytes']:>9.0f} {r['cpu']:>11.3f} "
              f"{r['router_cpu']:>10.3f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
