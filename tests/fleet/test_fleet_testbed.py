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
