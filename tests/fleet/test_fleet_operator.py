"""The fleet over several machines of docs/fleets.md, on one host: credentials made once (``--make-credentials``), the
fleet's router (``fleet --router --listen tls/...``), two drones joining it from one process (``fleet --connect``),
one from its own (``run --fleet``), and the operator (``ctl --fleet``) on the router's endpoint with the operator's
identity, or from a member's output folder alone (``--run DIR``: its ``fleet.json``)."""

import json
import os
import subprocess
import sys
from pathlib import Path

from aeroexec.cli.main import main
from aeroexec.fleet.transport import free_endpoint
from processes import HOVER, TOKEN, aeroexec, stop, wait_for_line, wait_for_lines


def ctl(*args: str, cwd: Path, token: str | None = None) -> subprocess.CompletedProcess:
    """``aeroexec ctl`` as the operator types it; ``token`` in ``$AEROEXEC_FLEET_TOKEN`` when given."""
    env = {k: v for k, v in os.environ.items() if k != "AEROEXEC_FLEET_TOKEN"}
    if token is not None:
        env["AEROEXEC_FLEET_TOKEN"] = token
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "ctl", *args], capture_output=True, text=True,
                          timeout=120, env=env, cwd=cwd)


def test_the_operator_reaches_every_drone_of_a_router_and_members_fleet_and_names_those_that_did_not_answer(
        tmp_path):
    (tmp_path / "hover.py").write_text(HOVER)
    (tmp_path / "search.yaml").write_text(
        "fleet: search\nshare: [object, code]\ncredentials: creds\ndrones:\n  - {name: d1}\n  - {name: d2}\n"
        "  - {name: d3}\n")
    (tmp_path / "part.yaml").write_text(  # the fleet's file with missions for the drones of one machine
        "fleet: search\nshare: [object, code]\ncredentials: creds\ndrones:\n  - {name: d1, mission: hover.py}\n"
        "  - {name: d2, mission: hover.py, home: [3, 0]}\n  - {name: d3}\n")
    endpoint = free_endpoint("tls")
    assert main(["fleet", str(tmp_path / "search.yaml"), "--make-credentials", str(tmp_path / "creds"),
                 "--listen", endpoint]) == 0
    router = aeroexec("fleet", "search.yaml", "--router", "--listen", endpoint, "--output", "router", cwd=tmp_path)
    processes = [router]
    try:
        wait_for_line(router, "listening on", 60)
        pair = aeroexec("fleet", "part.yaml", "--connect", endpoint, "--plain", "--speed", "1", "--output", "pair",
                        cwd=tmp_path)
        processes.append(pair)
        flying = wait_for_lines(pair, [("d1 |", "drone_takeoff_complete"), ("d2 |", "drone_takeoff_complete")], 120)

        # the README's operator line: every drone that flies answers, the one that does not is named
        status = ctl("--fleet", "search", "status", "--credentials", "creds", "--connect", endpoint, cwd=tmp_path,
                     token=TOKEN)
        assert status.returncode == 1, status.stderr
        assert "d1: running" in status.stdout and "d2: running" in status.stdout, status.stdout + status.stderr
        assert "d3: did not answer" in status.stderr
        assert "1 of 3 drones of fleet search did not answer: d3" in status.stderr

        d3 = aeroexec("run", "hover.py", "--fleet", "search", "--name", "d3", "--credentials", "creds/d3.pem",
                      "--connect", endpoint, "--plain", "--output", "d3", cwd=tmp_path)
        processes.append(d3)
        joined = wait_for_line(d3, "drone_takeoff_complete", 120)

        # from a member's output folder alone: its fleet.json holds the endpoint, token, operator and drones
        status = ctl("--fleet", "search", "status", "--run", "pair", cwd=tmp_path)
        assert status.returncode == 0, status.stdout + status.stderr
        assert [line.split(":")[0] for line in status.stdout.splitlines() if not line.startswith(" ")] == [
            "d1", "d2", "d3"]
        assert status.stdout.count("in_air") + status.stdout.count("flying") >= 3, status.stdout
        aborted = ctl("--fleet", "search", "abort", "--run", "pair", cwd=tmp_path)
        assert aborted.returncode == 0, aborted.stdout + aborted.stderr
        for drone in ("d1", "d2", "d3"):
            assert f"{drone}: mission aborted" in aborted.stdout, aborted.stdout
        pair_out, _ = pair.communicate(timeout=120)
        d3_out, _ = d3.communicate(timeout=120)
    finally:
        stop(*processes)
    pair_out, d3_out = "".join(flying) + pair_out, "".join(joined) + d3_out
    assert pair.returncode == 1 and d3.returncode != 0  # aborted: not completed
    for drone in ("d1", "d2"):
        summary = next(line for line in pair_out.splitlines() if line.startswith(f"{drone}: hover.py"))
        assert "aborted" in summary and "landed at" in summary, summary
    assert "hover.py: aborted" in d3_out and "drone_disarmed" in d3_out, d3_out[-3000:]


def test_the_operator_names_every_drone_of_the_routers_roster_that_did_not_answer_even_when_none_did(tmp_path):
    """The operator's endpoint and identity given and the router's folder named (``--run``): the drones ctl expects
    are the roster of the router's fleet.json, so with no drone flying yet each is named, not only 'none answered'."""
    (tmp_path / "search.yaml").write_text("fleet: search\ncredentials: creds\ndrones:\n  - {name: d1}\n"
                                          "  - {name: d2}\n")
    endpoint = free_endpoint("tls")
    assert main(["fleet", str(tmp_path / "search.yaml"), "--make-credentials", str(tmp_path / "creds"),
                 "--listen", endpoint]) == 0
    router = aeroexec("fleet", "search.yaml", "--router", "--listen", endpoint, "--output", "router", cwd=tmp_path)
    try:
        wait_for_line(router, "listening on", 60)
        status = ctl("--fleet", "search", "status", "--credentials", "creds", "--connect", endpoint, "--run",
                     "router", cwd=tmp_path, token=TOKEN)
    finally:
        stop(router)
    assert status.returncode == 1, status.stdout + status.stderr
    assert "d1: did not answer" in status.stderr and "d2: did not answer" in status.stderr, status.stderr
    assert "no drone of fleet search answered" in status.stderr


def test_a_command_sent_through_two_routers_is_run_once_and_answered_while_one_router_is_down(tmp_path):
    """The docs' operator names every router (``--connect`` for each): a command goes through each at once, the drone
    runs it once whichever copy comes first and answers both; with one router gone the other path still carries it,
    also from a router's folder alone (``--run DIR``: its fleet.json names the routers it links to)."""
    (tmp_path / "hover.py").write_text(HOVER)
    (tmp_path / "search.yaml").write_text("fleet: search\ncredentials: creds\ndrones:\n  - {name: d1}\n")
    first, second = free_endpoint("tls"), free_endpoint("tls")
    assert main(["fleet", str(tmp_path / "search.yaml"), "--make-credentials", str(tmp_path / "creds"),
                 "--listen", first, "--listen", second]) == 0
    router = aeroexec("fleet", "search.yaml", "--router", "--listen", first, "--output", "r1", cwd=tmp_path)
    processes = [router]
    try:
        wait_for_line(router, "listening on", 60)
        linked = aeroexec("fleet", "search.yaml", "--router", "--listen", second, "--connect", first, "--output", "r2",
                          cwd=tmp_path)
        processes.append(linked)
        wait_for_line(linked, "listening on", 60)
        d1 = aeroexec("run", "hover.py", "--fleet", "search", "--name", "d1", "--credentials", "creds/d1.pem",
                      "--connect", second, "--plain", "--output", "d1", cwd=tmp_path)
        processes.append(d1)
        flying = wait_for_line(d1, "drone_takeoff_complete", 120)
        both = ("--credentials", "creds", "--connect", first, "--connect", second, "--run", "r1")

        paused = ctl("--fleet", "search", "pause", *both, cwd=tmp_path, token=TOKEN)
        assert paused.returncode == 0 and paused.stdout.startswith("d1: "), paused.stdout + paused.stderr
        flying += wait_for_line(d1, "operator_command", 60)
        resumed = ctl("--fleet", "search", "resume", *both, cwd=tmp_path, token=TOKEN)
        assert resumed.returncode == 0, resumed.stdout + resumed.stderr

        # the linked router's fleet.json names both routers: `--run r2` alone gives the operator both paths
        assert json.loads((tmp_path / "r2" / "fleet.json").read_text())["endpoints"] == [second, first]
        stop(router)  # the first router gone: the second path carries the command alone
        aborted = ctl("--fleet", "search", "abort", "--run", "r2", cwd=tmp_path)
        assert aborted.returncode == 0 and "d1: mission aborted" in aborted.stdout, aborted.stdout + aborted.stderr
        out, _ = d1.communicate(timeout=120)
    finally:
        stop(*processes)
    commands = [line for line in "".join(flying).splitlines() + out.splitlines() if "operator_command" in line]
    assert [c.split("operator_command")[1].split(":")[1].strip() for c in commands] == ["pause", "resume", "abort"], \
        commands


def test_a_ground_station_console_sends_each_line_as_a_command_through_links_it_keeps_open(tmp_path):
    """``ctl --fleet NAME --stdin --json``: a line in, the drones' answers out as one JSON line, the links opened once;
    a line that is no command is named by its line number and the console goes on."""
    (tmp_path / "hover.py").write_text(HOVER)
    (tmp_path / "search.yaml").write_text("fleet: search\ncredentials: creds\ndrones:\n  - {name: d1}\n")
    endpoint = free_endpoint("tls")
    assert main(["fleet", str(tmp_path / "search.yaml"), "--make-credentials", str(tmp_path / "creds"),
                 "--listen", endpoint]) == 0
    router = aeroexec("fleet", "search.yaml", "--router", "--listen", endpoint, "--output", "r1", cwd=tmp_path)
    processes = [router]
    try:
        wait_for_line(router, "listening on", 60)
        d1 = aeroexec("run", "hover.py", "--fleet", "search", "--name", "d1", "--credentials", "creds/d1.pem",
                      "--connect", endpoint, "--plain", "--output", "d1", cwd=tmp_path)
        processes.append(d1)
        flying = wait_for_line(d1, "drone_takeoff_complete", 120)
        console = subprocess.run(
            [sys.executable, "-m", "aeroexec.cli.main", "ctl", "--fleet", "search", "--stdin", "--json", "--run", "r1"],
            input="status\nfly to the moon\n\nadd 'object(marker_9, aruco)' --drone d1\nabort\n", capture_output=True,
            text=True, timeout=120, cwd=tmp_path)
        out, _ = d1.communicate(timeout=120)
    finally:
        stop(*processes)
    answers = [json.loads(line) for line in console.stdout.splitlines()]
    assert [sorted(a) for a in answers] == [["d1"], ["d1"], ["d1"]], console.stdout + console.stderr
    assert "battery" in json.dumps(answers[0]["d1"]["status"]) and answers[2]["d1"]["ok"], answers
    assert "<stdin>:2: not a fleet command: fly to the moon" in console.stderr, console.stderr
    assert console.returncode == 1  # one line was no command
    commands = [line for line in "".join(flying).splitlines() + out.splitlines() if "operator_command" in line]
    assert [c.split("operator_command: ")[1].split(":")[0] for c in commands] == [
        "add object(marker_9, aruco)", "abort"], commands  # each once (a status is not a command's event)
    assert "hover.py: aborted" in out
