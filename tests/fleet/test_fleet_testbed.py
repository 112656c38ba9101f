"""The README's fleet over several machines, on hosts of their own (network namespaces on one switch,
:mod:`testbed`): a router on each host, linked; a drone on each host joined to its own host's router; the operator
on the first host commands both through the routers, with 20 % of the packets each host receives dropped."""

import os

import pytest
from processes import HOVER, TOKEN, Output, stop
from testbed import Testbed

PORT = 7447  # each host has its own network stack: the README's port is free on every one


@pytest.fixture
def testbed():
    bed = Testbed()
    yield bed
    bed.close()


def test_two_drones_on_two_hosts_fly_through_their_routers_and_the_operator_aborts_both_under_loss(testbed,
                                                                                                      tmp_path):
    a, b = testbed.host("a"), testbed.host("b")
    (tmp_path / "hover.py").write_text(HOVER)
    (tmp_path / "search.yaml").write_text("fleet: search\ncredentials: creds\ndrones:\n  - {name: d1}\n"
                                          "  - {name: d2}\n")
    env = {**os.environ, "AEROEXEC_FLEET_TOKEN": TOKEN}
    at_a, at_b = f"tls/{a.address}:{PORT}", f"tls/{b.address}:{PORT}"
    made = a.run("aeroexec", "fleet", "search.yaml", "--make-credentials", "creds", "--listen", at_a, "--listen",
                 at_b, cwd=tmp_path, env=env)
    assert made.returncode == 0, made.stdout + made.stderr
    processes = []

    def start(host, *words: str) -> Output:
        process = host.popen("aeroexec", *words, cwd=tmp_path, env=env)
        processes.append(process)
        return Output(process)

    try:
        router_a = start(a, "fleet", "search.yaml", "--router", "--listen", at_a, "--output", "router-a")
        router_a.wait(lambda lines: any("listening on" in line for line in lines), "router a", 60)
        router_b = start(b, "fleet", "search.yaml", "--router", "--listen", at_b, "--connect", at_a, "--output",
                         "router-b")
        router_b.wait(lambda lines: any("listening on" in line for line in lines), "router b", 60)
        drones = {name: start(host, "run", "hover.py", "--fleet", "search", "--name", name, "--credentials", "creds",
                              "--connect", endpoint, "--plain", "--output", name)
                  for name, host, endpoint in (("d1", a, at_a), ("d2", b, at_b))}
        for name, other in (("d1", "d2"), ("d2", "d1")):  # each hears the other, across the hosts and routers
            drones[name].wait(lambda lines, other=other: any(f"fleet_drone_heard: {other} is in the fleet" in line
                                                             for line in lines)
                              and any("drone_takeoff_complete" in line for line in lines), f"{name} flying", 120)
        testbed.lose(a, 20)
        testbed.lose(b, 20)
        operator = env  # the README's operator line: AEROEXEC_FLEET_TOKEN=T aeroexec ctl --fleet ...
        status = a.run("aeroexec", "ctl", "--fleet", "search", "status", "--credentials", "creds", "--connect", at_a,
                       cwd=tmp_path, env=operator)
        assert status.returncode == 0, status.stdout + status.stderr
        assert "d1: running" in status.stdout and "d2: running" in status.stdout, status.stdout
        aborted = a.run("aeroexec", "ctl", "--fleet", "search", "abort", "--credentials", "creds", "--connect", at_a,
                        cwd=tmp_path, env=operator)
        assert aborted.returncode == 0, aborted.stdout + aborted.stderr
        assert "d1: mission aborted" in aborted.stdout and "d2: mission aborted" in aborted.stdout, aborted.stdout
        for name, out in drones.items():
            out.process.wait(120)
            out.wait(lambda lines: lines[-1:] == [""], f"the end of {name}'s output", 30)
    finally:
        stop(*processes)
    for out in drones.values():
        assert out.process.returncode != 0, out.text[-3000:]  # aborted: not completed
        assert "hover.py: aborted" in out.text and "drone_disarmed" in out.text, out.text[-3000:]


def test_a_host_cut_off_keeps_flying_is_named_by_the_operator_and_is_heard_again_and_commanded_after_the_heal(
        testbed, tmp_path):
    """Host b (its router and d2) is cut off the network: d1 reports d2 silent, the operator on host a hears d1 and
    names d2 as not answering, the operator on host b reaches d2, which flies on; after the heal the routers link
    again without anyone's help, d1 hears d2 again, and one ctl abort reaches both."""
    a, b = testbed.host("a"), testbed.host("b")
    (tmp_path / "hover.py").write_text(HOVER)
    (tmp_path / "search.yaml").write_text("fleet: search\ncredentials: creds\ndrones:\n  - {name: d1}\n"
                                          "  - {name: d2}\n")
    env = {**os.environ, "AEROEXEC_FLEET_TOKEN": TOKEN}
    at_a, at_b = f"tls/{a.address}:{PORT}", f"tls/{b.address}:{PORT}"
    made = a.run("aeroexec", "fleet", "search.yaml", "--make-credentials", "creds", "--listen", at_a, "--listen",
                 at_b, cwd=tmp_path, env=env)
    assert made.returncode == 0, made.stdout + made.stderr
    processes = []

    def start(host, *words: str) -> Output:
        process = host.popen("aeroexec", *words, cwd=tmp_path, env=env)
        processes.append(process)
        return Output(process)

    def seen(out: Output, text: str, after: int = 0) -> bool:
        return any(text in line for line in out.lines[after:])

    def ctl(host, endpoint: str, command: str):
        return host.run("aeroexec", "ctl", "--fleet", "search", command, "--credentials", "creds", "--connect",
                        endpoint, cwd=tmp_path, env=env)

    try:
        router_a = start(a, "fleet", "search.yaml", "--router", "--listen", at_a, "--output", "router-a")
        router_a.wait(lambda lines: seen(router_a, "listening on"), "router a", 60)
        router_b = start(b, "fleet", "search.yaml", "--router", "--listen", at_b, "--connect", at_a, "--output",
                         "router-b")
        router_b.wait(lambda lines: seen(router_b, "listening on"), "router b", 60)
        d1 = start(a, "run", "hover.py", "--fleet", "search", "--name", "d1", "--credentials", "creds", "--connect",
                   at_a, "--plain", "--output", "d1")
        d2 = start(b, "run", "hover.py", "--fleet", "search", "--name", "d2", "--credentials", "creds", "--connect",
                   at_b, "--plain", "--output", "d2")
        for out, other in ((d1, "d2"), (d2, "d1")):
            out.wait(lambda lines, out=out, other=other: seen(out, f"fleet_drone_heard: {other} is in the fleet")
                     and seen(out, "drone_takeoff_complete"), f"flying and hearing {other}", 120)

        testbed.cut(b)
        d1.wait(lambda lines: seen(d1, "fleet_drone_silent: d2"), "d2 silent for d1", 120)
        cut_off = len(d2.lines)
        status = ctl(a, at_a, "status")
        assert status.returncode == 1, status.stdout + status.stderr
        assert "d1: running" in status.stdout and "d2: did not answer" in status.stderr, status.stdout + status.stderr
        there = ctl(b, at_b, "status")  # the operator on the cut-off host still reaches its drone, in the air
        assert "d2: running" in there.stdout and "in_air" in there.stdout, there.stdout + there.stderr
        assert "d1: did not answer" in there.stderr, there.stderr

        testbed.heal(b)
        healed = len(d1.lines)
        d1.wait(lambda lines: seen(d1, "d2 is heard again", healed), "d2 heard again after the heal", 120)
        aborted = ctl(a, at_a, "abort")
        assert aborted.returncode == 0, aborted.stdout + aborted.stderr
        assert "d1: mission aborted" in aborted.stdout and "d2: mission aborted" in aborted.stdout, aborted.stdout
        for out in (d1, d2):
            out.process.wait(120)
            out.wait(lambda lines: lines[-1:] == [""], "the end of the output", 30)
    finally:
        stop(*processes)
    commanded = next(n for n, line in enumerate(d2.lines) if "aborted by the operator" in line)
    flew_on = d2.lines[cut_off:commanded]  # from the cut to the operator's abort: d2 flew on, nothing landed it
    assert not any("LAND" in line or "landed" in line for line in flew_on), d2.text[-3000:]
    for out in (d1, d2):
        assert "hover.py: aborted" in out.text and "drone_disarmed" in out.text, out.text[-3000:]
