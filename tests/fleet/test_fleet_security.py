"""A fleet believes only its own drones. A rogue Zenoh session (a) without credentials, (b) with another drone's
certificate, (c) as a member publishing on another member's keys, (d) sharing beliefs about the receivers' own state
and predicates outside the share list, (e) flooding 100,000 messages: nothing it says reaches a drone's memory, no
drone does anything else than in a run nobody attacked, and each refusal is logged once per interval with its count.
"""

import json
import re
import threading
import time
from pathlib import Path

import pytest
import zenoh
from aeroexec.cli.main import main
from aeroexec.fleet.credentials import Authority
from aeroexec.fleet.payloads import tick
from aeroexec.fleet.transport import config, free_endpoint
from patience import hang_guard
from processes import MISSIONS, aeroexec, stop, wait_for_line

FLOOD = 100_000
LIES = ["charge(battery, 5)", "flight_state(self, landed)", "object(d1, enemy)", "object(d3, enemy)", "code(d2, 7)",
        "position(d2, (40, 40, 30))", "seen(self, marker_3)", "said(d1, code(m9, 3))"]  # about receivers, not shared
TRACES = ("enemy", "battery, 5", "40.0, 40.0", "m9", "m_stolen", "d9")  # what must reach no memory


def fleet_file(folder: Path, flown: tuple[str, ...], certificates: bool = False) -> Path:
    homes = {"d1": -15, "d2": -9, "d3": -3}
    lines = ["fleet: search", "share: [object, code]", "credentials: creds", "drones:"]
    for drone, x in homes.items():
        if drone in flown:
            named = f", certificate: creds/{drone}.pem, key: creds/{drone}.key" if certificates else ""
            lines.append(f"  - {{name: {drone}, mission: {MISSIONS / 'fleet_search.py'}, home: [{x}, -1]{named}}}")
        else:
            lines.append(f"  - {{name: {drone}}}")
    lines.append("  - {name: d9}   # a member flying elsewhere, whose credentials the rogue holds")
    path = folder / "search.yaml"
    path.write_text("\n".join(lines) + "\n")
    assert main(["fleet", str(path), "--make-credentials", str(folder / "creds")]) == 0
    return path


def rogue_session(endpoint: str, ca: Path | None = None, certificate: Path | None = None, key: Path | None = None):
    """A Zenoh client of ``endpoint`` with what it holds (it does not check who it talks to)."""
    c = config("client", connect=[endpoint])
    tls = {"verify_name_on_connect": False}
    if ca is not None:
        tls["root_ca_certificate"] = str(ca)
    if certificate is not None:
        tls |= {"enable_mtls": True, "connect_certificate": str(certificate), "connect_private_key": str(key)}
    c.insert_json5("transport/link/tls", json.dumps(tls))
    return zenoh.open(c)


class Rogue(threading.Thread):
    """Every attack of the module docstring, once the fleet's router answers; ``report`` says what happened."""

    def __init__(self, endpoint: str, creds: Path, stranger: Path, impostor: bool) -> None:
        super().__init__(daemon=True)
        self.endpoint, self.creds, self.stranger, self.impostor = endpoint, creds, stranger, impostor
        self.report: dict[str, object] = {}

    def run(self) -> None:
        ca = self.creds / "ca.pem"
        member = None
        deadline = time.monotonic() + 60
        while member is None and time.monotonic() < deadline:  # (wait for the router)
            try:
                member = rogue_session(self.endpoint, ca, self.creds / "d9.pem", self.creds / "d9.key")
            except zenoh.ZError:
                time.sleep(0.1)
        assert member is not None, "the rogue member never got in"
        self.report["joined"] = True
        refused = []
        for name, holding in [("(a) no certificate", {}),
                              ("(b) d2's certificate, not its key", {"certificate": self.creds / "d2.pem",
                                                                     "key": self.creds / "d9.key"}),
                              ("(b) a d2 of another CA", {"certificate": self.stranger / "d2.pem",
                                                          "key": self.stranger / "d2.key"})]:
            try:
                rogue_session(self.endpoint, ca, **holding).close()
            except zenoh.ZError:
                refused.append(name)
        self.report["refused"] = refused
        # (c) a member on another member's keys, lying about the sender in the payload too
        for fields in ([["telemetry", {"position": [40, 40, 30]}]], [["beliefs", {"beliefs": ["code(m9, 3)"]}]],
                       [["broadcast", {"text": "marker 3 found"}]]):
            member.put("aeroexec/search/d1/tick", tick("d1", fields))
            member.put("aeroexec/search/d9/tick", tick("d1", fields))
        if self.impostor:  # d2's own certificate and key, stolen, while d2 flies in the fleet's process
            stolen = rogue_session(self.endpoint, ca, self.creds / "d2.pem", self.creds / "d2.key")
            stolen.put("aeroexec/search/d2/tick", tick("d2", [["beliefs", {"beliefs": ["code(m_stolen, 3)"]}]]))
            stolen.close()
        # (d) on its own keys: about the receivers' own state, and predicates the fleet does not share
        member.put("aeroexec/search/d9/tick", tick("d9", [["beliefs", {"beliefs": LIES}],
                                                          ["telemetry", {"position": ["x", 1, 2]}]]))
        # (e) a flood: not JSON and lies on its own keys, another's keys, another version
        lies = tick("d9", [["beliefs", {"beliefs": LIES}]])
        kinds = [("aeroexec/search/d9/tick", b"{not json"), ("aeroexec/search/d9/tick", lies),
                 ("aeroexec/search/d1/tick", tick("d1", [["telemetry", {"position": [40, 40, 30]}]])),
                 ("aeroexec/search/d9/tick", json.dumps({"v": 99, "drone": "d9"}).encode())]
        publishers = [(member.declare_publisher(k, congestion_control=zenoh.CongestionControl.BLOCK), payload)
                      for k, payload in kinds]  # every message sent, none dropped on the way
        started = time.monotonic()
        for n in range(FLOOD):
            publisher, payload = publishers[n % len(publishers)]
            publisher.put(payload)
        self.report["flood_seconds"] = time.monotonic() - started
        time.sleep(0.5)
        member.close()


def events(folder: Path, drone: str) -> list[dict]:
    return [json.loads(line) for line in (folder / drone / "events.jsonl").read_text().splitlines()[1:]]


def check_refusal_lines(out: str) -> int:
    """Each sender and reason logged once, then counted; the number counted."""
    first = re.findall(r"refused an? (?:message|belief) from (\S+): (.+?)(?: \(.*\))?; more of the same", out)
    assert len(first) == len(set(first)), first
    counted = re.findall(r"refused ([\d,]+) more (?:message|belief)s? from (\S+) in the last", out)
    assert len([line for line in out.splitlines() if "refused" in line]) < 60, out[-3000:]
    return sum(int(n.replace(",", "")) for n, _ in counted)


def assert_untouched(log: list[dict]) -> None:
    for event in log:
        if event["kind"] != "fleet_refused":
            text = json.dumps(event)
            assert not any(trace in text for trace in TRACES), event


@pytest.fixture
def stranger(tmp_path):
    """The credentials of a d2 of another fleet's CA (same fleet name: only the CA tells them apart)."""
    Authority(tmp_path / "stranger", "search").issue("d2")
    return tmp_path / "stranger"


def test_a_rogue_session_changes_nothing_the_drones_of_a_fleet_in_one_process_do(tmp_path, stranger):
    path = fleet_file(tmp_path, ("d1", "d2", "d3"))
    assert main(["fleet", str(path), "--plain", "--quiet", "--output", str(tmp_path / "calm")]) == 0
    endpoint = free_endpoint("tls")
    attacked = aeroexec("fleet", str(path), "--plain", "--quiet", "--speed", "8", "--listen", endpoint, "--output",
                        str(tmp_path / "attacked"), cwd=tmp_path)
    try:
        flying = wait_for_line(attacked, "drones here", 30)
        rogue = Rogue(endpoint, tmp_path / "creds", stranger, impostor=True)
        rogue.start()
        out, _ = attacked.communicate(timeout=120)
    finally:
        stop(attacked)
    rogue.join(30)
    out = "".join(flying) + out
    assert attacked.returncode == 0, out[-3000:]
    assert rogue.report.get("joined") and "flood_seconds" in rogue.report, rogue.report
    assert rogue.report["refused"] == ["(a) no certificate", "(b) d2's certificate, not its key",
                                       "(b) a d2 of another CA"]
    for drone in ("d1", "d2", "d3"):
        calm, seen = events(tmp_path / "calm", drone), events(tmp_path / "attacked", drone)
        refusals = [(e["data"]["sender"], e["data"]["reason"]) for e in seen if e["kind"] == "fleet_refused"]
        assert refusals and len(refusals) == len(set(refusals)), refusals  # each new reason once
        assert [e for e in seen if e["kind"] not in ("fleet_refused", "log_closed")] == calm[:-1], drone  # the same
        assert_untouched(seen)
        assert ("d2", "not said by d2, which flies in this process (someone else on its keys)") in refusals \
            or drone == "d2"
        assert {("d9", "about this drone"), ("d9", "a predicate the sender does not share"),
                ("d9", "about another member (each drone speaks for itself)")} <= set(refusals)
    assert "from d9: not JSON" in out and "from d9: a predicate the sender does not share" in out
    assert check_refusal_lines(out) > 1000, out[-3000:]  # the flood, counted, not repeated


def test_a_fleet_across_two_processes_and_routers_flies_the_search_with_its_credentials(tmp_path, stranger):
    """Credentials made by `aeroexec fleet --make-credentials`; the fleet file names d1's and d2's certificates
    (one process flies both, one session each) and they join through the fleet's router; d3 flies in
    `aeroexec run --fleet` and joins through a second router of the fleet, linked to the first (as on another
    machine); the rogue attacks the first router meanwhile."""
    path = fleet_file(tmp_path, ("d1", "d2"), certificates=True)
    endpoint, other = free_endpoint("tls"), free_endpoint("tls")
    router = aeroexec("fleet", str(path), "--router", "--listen", endpoint, "--output", str(tmp_path / "router"),
                      cwd=tmp_path)
    processes = [router]
    try:
        wait_for_line(router, "listening on", 30)
        linked = aeroexec("fleet", str(path), "--router", "--listen", other, "--connect", endpoint, "--output",
                          str(tmp_path / "router2"), cwd=tmp_path)
        processes.append(linked)
        wait_for_line(linked, "listening on", 30)
        # d3 flies before the pair's process is up (seconds on a loaded machine) and waits 120 s of its time for
        # their news: at 2x that wait outlasts their start and the flood on the router (at 8x it ran out first)
        d3 = aeroexec("run", str(MISSIONS / "fleet_search.py"), "--fleet", "search", "--name", "d3", "--connect",
                      other, "--credentials", str(tmp_path / "creds" / "d3.pem"), "--share", "object", "--share",
                      "code", "--speed", "2", "--plain", "--output", str(tmp_path / "d3"), cwd=tmp_path)
        processes.append(d3)
        before = wait_for_line(d3, "joined fleet search", 30)
        pair = aeroexec("fleet", str(path), "--connect", endpoint, "--speed", "8", "--plain", "--output",
                        str(tmp_path / "pair"), cwd=tmp_path)
        processes.append(pair)
        flying = wait_for_line(pair, "drones here", 30)
        rogue = Rogue(endpoint, tmp_path / "creds", stranger, impostor=False)
        rogue.start()
        pair_out, _ = pair.communicate(timeout=hang_guard(120))
        d3_out, _ = d3.communicate(timeout=hang_guard(120))
        rogue.join(hang_guard(30))
    finally:
        stop(*processes)
    d3_out, pair_out = "".join(before) + d3_out, "".join(flying) + pair_out
    assert pair.returncode == 0, pair_out[-3000:]
    assert d3.returncode == 0, d3_out[-3000:]
    assert rogue.report["refused"] == ["(a) no certificate", "(b) d2's certificate, not its key",
                                       "(b) a d2 of another CA"]
    summary = [line for line in pair_out.splitlines() if line.startswith(("d1:", "d2:"))]
    assert len(summary) == 2 and all("completed" in line for line in summary), summary
    heard = [e for e in events(tmp_path, "d3") if e["kind"] in ("fleet_belief", "message_received")]
    assert any("code(marker_3, 3)" in e["detail"] or "marker 3 found" in e["detail"] for e in heard), heard
    for log in (events(tmp_path / "pair", "d1"), events(tmp_path / "pair", "d2"), events(tmp_path, "d3")):
        assert_untouched(log)
        assert any(e["kind"] == "fleet_refused" and e["data"]["sender"] == "d9" for e in log)
    for out in (pair_out, d3_out):
        assert "from d9: not JSON" in out
        check_refusal_lines(out)
