"""The fleet of docs/fleet-testbed.md under a hostile network: 6 drones over 3 hosts, a router on each (linked to
the first host's), the operator on a fourth host; every packet between hosts 200 ± 50 ms late (reordered, 1 %
duplicated: the testbed's delaying relay) and 20 % of those reaching each host dropped. One host is cut off for
30 s and healed, one router is killed and started again; the operator's commands (from a console that keeps its
links to every router open, `ctl --stdin`, and from one-shot `ctl`) reach every reachable drone and name the
others, beliefs and positions converge within the stated time after the heal, and every drone is landed at
the end."""

import signal
import time

import pytest
from hosts import FleetOfHosts, mates_heard, percentile, reported_silent, seen, when
from patience import hang_guard
from testbed import Latency, Testbed

CUT_FOR = 30.0  # seconds one host is cut off: the fault itself, not a wait
#: The stated bound (docs/fleet-testbed.md): after a heal, every drone hears every other again and the beliefs said
#: meanwhile are believed on both sides within this many seconds (measured 6 to 24 s with the hosts'
#: net.ipv4.tcp_retries2=5, as the docs set it on the routers' machines; 18 to 70 s with the kernel's 15).
CONVERGE = 60.0
TRIES = 3  # the operator sends the abort again to each drone named as not answering, at most this many times
FOUND = "object(marker_9, aruco)"


@pytest.fixture
def fleet(tmp_path):
    bed = Testbed(Latency(200, 50, reorder=True, duplicate=1))
    hosts = None
    try:
        hosts = FleetOfHosts(bed, tmp_path)
        yield hosts
    finally:
        if hosts is not None:
            hosts.close()
        bed.close()


def test_six_drones_on_three_hosts_under_latency_and_loss_ride_out_a_partition_and_a_router_restart(fleet):
    guard = hang_guard(120)
    fleet.start(guard, loss=20)
    h1, h2, h3 = fleet.hosts
    d = fleet.drones
    console = fleet.console(guard)  # the operator's ground station: ctl --stdin, its links to each router kept open

    status = console.ctl("status")
    assert status.done.returncode == 0, status.done.stdout + status.done.stderr
    assert sorted(status.answers) == fleet.names and all(a["ok"] for a in status.answers.values()), \
        (status.answers, status.done.stderr)

    # host 3 (d5, d6 and their router) cut off for 30 s: the others report them silent (or have, and not heard them
    # again since: under loss a link stalls for seconds before the cut), the operator names them
    marks = {name: len(out.lines) for name, out in d.items()}
    cut = time.monotonic()
    fleet.bed.cut(h3)
    for name in ("d1", "d2", "d3", "d4"):
        for mate in ("d5", "d6"):
            d[name].wait(lambda lines, mate=mate, n=name: reported_silent(lines, mate, marks[n]),
                         f"{mate} silent for {name}", guard)
    said = fleet.ctl("add", FOUND, "--drone", "d1")  # said during the partition: heard on host 3 only after it
    assert said.done.returncode == 0 and said.answers["d1"]["ok"], said.done.stdout + said.done.stderr
    partial = console.ctl("status")
    assert partial.done.returncode == 1, partial.done.stdout + partial.done.stderr
    assert {n for n, a in partial.answers.items() if a.get("answered") is False} == {"d5", "d6"}, \
        (partial.answers, partial.done.stderr)
    assert all(partial.answers[n]["ok"] for n in ("d1", "d2", "d3", "d4")), (partial.answers, partial.done.stderr)
    for name in ("d2", "d3", "d4"):
        d[name].wait(lambda lines: seen(lines, f"fleet_belief: from d1: {FOUND}"), f"{name} believing d1", guard)
    time.sleep(max(0.0, CUT_FOR - (time.monotonic() - cut)))  # the partition lasts its 30 s
    assert not any(seen(d[n].lines, FOUND) for n in ("d5", "d6")), "host 3 heard d1 through the partition"
    healed_at = {name: len(out.lines) for name, out in d.items()}
    heal = time.monotonic()
    fleet.bed.heal(h3)

    # converged: every drone hears every other again, d5 and d6 believe what d1 said meanwhile
    expected = {name: [f"{mate} is heard again" for mate in (("d5", "d6") if name in ("d1", "d2", "d3", "d4") else
                                                             ("d1", "d2", "d3", "d4"))] for name in fleet.names}
    expected["d5"].append(f"fleet_belief: from d1: {FOUND}")
    expected["d6"].append(f"fleet_belief: from d1: {FOUND}")
    for name, texts in expected.items():
        d[name].wait(lambda lines, texts=texts, n=name: all(seen(lines, t, healed_at[n]) for t in texts),
                     f"{name} converged after the heal", guard)
    converged = max(when(d[name], text, healed_at[name]) for name, texts in expected.items() for text in texts) - heal
    print(f"converged {converged:.1f} s after the heal")
    assert converged <= CONVERGE, f"converged {converged:.1f} s after the heal, stated {CONVERGE:g} s"
    for name in ("d5", "d6"):  # cut off, they flew their mission on: nothing landed them
        assert not any("LAND" in line or "landed" in line for line in d[name].lines[:healed_at[name]]), d[name].text

    # host 2's router killed and started again with the same command: its drones and the other routers rejoin it
    marks = {name: len(out.lines) for name, out in d.items()}
    fleet.kill_router(h2)
    for mate in ("d3", "d4"):
        d["d1"].wait(lambda lines, mate=mate: reported_silent(lines, mate, marks["d1"]), f"{mate} silent for d1", guard)
    fleet.router(h2, guard)
    for name, mates in (("d1", ("d3", "d4")), ("d6", ("d3", "d4")), ("d3", ("d1", "d6")), ("d4", ("d1", "d6"))):
        for mate in mates:
            d[name].wait(lambda lines, mate=mate, n=name: seen(lines, f"{mate} is heard again", marks[n]),
                         f"{mate} heard again by {name} after the router's restart", guard)

    # the operator's abort: every drone of the roster answers or is named, the operator sends it again to those
    # named (a command's answers wait 8 s; a link stalled longer by TCP's retransmissions misses them), each lands
    aborted = console.ctl("abort")
    assert sorted(aborted.answers) == fleet.names, (aborted.answers, aborted.done.stderr)
    missed = sorted(n for n, a in aborted.answers.items() if a.get("answered") is False)
    assert all(a["ok"] for n, a in aborted.answers.items() if n not in missed), aborted.answers
    print(f"the first abort reached {len(fleet.names) - len(missed)} of {len(fleet.names)} drones; named {missed}")
    for name in missed:  # answered (an abort that came twice may be refused as the flight already ends)
        again = []
        while len(again) < TRIES and not any(answered(c, name) for c in again):
            again.append(fleet.ctl("abort", "--drone", name))
        assert answered(again[-1], name), [c.done.stdout + c.done.stderr for c in again]
    # how long each command took to reach each drone (the operator's clock against the drone's: one machine's):
    # printed, not asserted (200 ms a hop and a fifth of the packets lost: over 2 s for some, see the docs)
    reach = [r for command in fleet.commands for r in command.reached.values()]
    print(f"commands reached their drones in p50 {percentile(reach, 50):.2f} s, p99 {percentile(reach, 99):.2f} s, "
          f"max {max(reach):.2f} s ({len(reach)}); the abort in {sorted(aborted.reached.values())}")
    assert console.close() != 0  # some command was not done by every drone (the partition's status)
    fleet.ended(guard)
    for out in d.values():
        assert out.process.returncode not in (0, None), out.text[-3000:]  # aborted: not completed
        assert "hover.py: aborted" in out.text and "drone_disarmed" in out.text, out.text[-3000:]
    assert all(mates_heard(out.lines) >= len(fleet.names) - 1 for out in d.values())
    for router in fleet.routers.values():
        router.process.send_signal(signal.SIGTERM)


def answered(command, drone: str) -> bool:
    return drone in command.answers and command.answers[drone].get("answered", True)
