"""Agreement for beliefs that decide: with ``trust: {code: 2}`` in the fleet file, one member (whose key an
attacker holds) saying a fake ``code(marker_77, 3)`` and broadcasting it does not end the other drones' search; a
second member saying it does."""

import threading
from pathlib import Path

from aeroexec.cli.main import main
from aeroexec.fleet.credentials import Identity
from aeroexec.fleet.payloads import tick
from aeroexec.fleet.transport import free_endpoint, open_session
from processes import Output, aeroexec, stop

SEARCH = '''"""Search the south of home, leg after leg, until a marker with code 3 is known (seen, or from the fleet);
then go home and land."""
import aeroexec.engine.api as api


def mission():
    _, home = api.consult_belief("position(self, (?X, ?Y, ?Z))")
    x, y = round(home["?X"], 1), round(home["?Y"], 1)
    api.execute_behavior("TAKE_OFF", altitude=4)
    legs = 0
    while not api.true_belief("code(?M, 3)") and legs < 400:
        api.execute_behavior("GO_TO_POINT", coordinates=[x + (2 if legs % 2 else -2), -12, 4])
        legs += 1
    api.execute_behavior("GO_TO_POINT", coordinates=[x, y, 4])
    api.execute_behavior("LAND")
    if not api.true_belief("code(?M, 3)"):
        raise RuntimeError("no marker with code 3 is known")
'''


class Liar(threading.Thread):
    """A member of the fleet (its key stolen) saying a fake code 3 and broadcasting it, until told to stop."""

    def __init__(self, endpoint: str, creds: Path, name: str) -> None:
        super().__init__(daemon=True)
        self.endpoint, self.creds, self.name = endpoint, creds, name
        self.stopped = threading.Event()

    def run(self) -> None:
        session = open_session("client", connect=[self.endpoint],
                               identity=Identity.at(self.creds, self.name).read("search"))
        try:
            while not self.stopped.wait(0.2):
                session.put(f"aeroexec/search/{self.name}/tick", tick(self.name, [
                    ["beliefs", {"beliefs": ["code(marker_77, 3)", "object(marker_77, aruco)"]}],
                    ["broadcast", {"text": "marker 3 found at (0, -12)"}]]))
        finally:
            session.close()


def after(lines: list[str], drone: str, first: str, then: str, times: int) -> bool:
    """``drone``'s line holding ``then`` came ``times`` times after its first line holding ``first``."""
    mine = [line for line in lines if line.startswith(f"{drone:>4} | ")]
    start = next((n for n, line in enumerate(mine) if first in line), None)
    return start is not None and sum(then in line for line in mine[start:]) >= times


def test_with_trust_one_members_fake_code_does_not_end_the_search_and_two_members_do(tmp_path):
    (tmp_path / "search.py").write_text(SEARCH)
    (tmp_path / "search.yaml").write_text(
        "fleet: search\nshare: [object, code]\ncredentials: creds\ntrust: {code: 2}\ndrones:\n"
        "  - {name: d1, mission: search.py, home: [5, -1]}\n  - {name: d2, mission: search.py, home: [11, -1]}\n"
        "  - {name: d8}\n  - {name: d9}   # members flying elsewhere, whose keys the attacker holds\n")
    assert main(["fleet", str(tmp_path / "search.yaml"), "--make-credentials", str(tmp_path / "creds")]) == 0
    endpoint = free_endpoint("tls")
    fleet = aeroexec("fleet", "search.yaml", "--listen", endpoint, "--plain", "--speed", "2", "--output", "out",
                     cwd=tmp_path)
    out = Output(fleet)
    liars = [Liar(endpoint, tmp_path / "creds", name) for name in ("d9", "d8")]
    try:
        out.wait(lambda lines: all(after(lines, d, "drone_takeoff_complete", "", 1) for d in ("d1", "d2")),
                 "both drones in the air", 120)
        liars[0].start()
        # each drone hears d9's claim, holds it as said(d9, ...) only, and goes on searching: two more legs (the
        # second one started after a look at its beliefs that came after the claim)
        out.wait(lambda lines: all(after(lines, d, "fleet_claim: from d9: code(marker_77, 3)",
                                         "activated GO_TO_POINT", 2) for d in ("d1", "d2")),
                 "the search going on after d9's claim", 120)
        assert "code(marker_77, 3)" not in "".join(line for line in out.lines if "fleet_belief" in line)
        assert "(said by 1 of the 2 members needed to believe it)" in out.text
        liars[1].start()  # a second member agrees: now the drones believe it and end the search
        fleet.wait(180)
        out.wait(lambda lines: lines[-1:] == [""], "the end of the fleet's output", 30)
    finally:
        for liar in liars:
            liar.stopped.set()
        stop(fleet)
    text = out.text
    assert fleet.returncode == 0, text[-3000:]
    for drone in ("d1", "d2"):
        assert f"{drone:>4} | " in text
        assert any(line.startswith(f"{drone:>4} | ") and "fleet_belief: from d8, d9: code(marker_77, 3)" in line
                   for line in out.lines), text[-3000:]
        summary = next(line for line in out.lines if line.startswith(f"{drone}: search.py"))
        assert "completed" in summary and "landed" in summary, summary
