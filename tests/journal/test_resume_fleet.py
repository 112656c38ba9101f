"""A drone of a fleet resumes into the fleet it left: the relay's scout (missions/relay_scout.py), killed with
SIGKILL before it broadcast "area clear", is resumed with ``aeroexec run --resume``; it joins the fleet again as
itself (the fleet's token from its run folder), the carrier sees it silent then heard again, gets the message once
and finishes its mission."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from aeroexec.fleet.transport import free_endpoint
from aeroexec.flight.journal import Journal, resume_spec
from patience import hang_guard

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fleet"))
from processes import MISSIONS, aeroexec, stop, wait_for_line  # noqa: E402  (tests/fleet/processes.py)


class Output:
    """A process's output lines as they come."""

    def __init__(self, process: subprocess.Popen) -> None:
        self.process, self.lines = process, []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.process.stdout:
            self.lines.append(line)

    def wait_for(self, text: str, timeout: float) -> None:
        deadline = time.monotonic() + hang_guard(timeout)
        while not any(text in line for line in self.lines):
            if time.monotonic() > deadline:
                raise AssertionError(f"{text!r} not seen: {''.join(self.lines)[-3000:]}")
            time.sleep(0.05)

    @property
    def text(self) -> str:
        return "".join(self.lines)


@pytest.fixture
def router(tmp_path):
    """The relay fleet's router (mutual TLS) on a free port: (its endpoint, the credentials it made)."""
    file = tmp_path / "relay.yaml"
    file.write_text("fleet: relay\ndrones:\n  - {name: carrier}\n  - {name: scout}\n")
    endpoint = free_endpoint("tls")
    process = aeroexec("fleet", str(file), "--router", "--listen", endpoint, "--output", str(tmp_path / "router"),
                       cwd=tmp_path)
    wait_for_line(process, "listening on", 30)
    yield endpoint, tmp_path / "router" / "credentials"
    process.send_signal(signal.SIGTERM)
    process.wait(10)


def test_a_drone_killed_in_a_fleet_resumes_into_it(router, tmp_path):
    endpoint, credentials = router
    common = ("--fleet", "relay", "--connect", endpoint, "--credentials", str(credentials), "--plain",
              "--trust", "code=2")
    carrier = aeroexec("run", str(MISSIONS / "relay_carrier.py"), "--name", "carrier", "--output",
                       str(tmp_path / "carrier"), "--speed", "4", *common, cwd=tmp_path)
    scout = resumed = None
    try:
        heard = Output(carrier)
        heard.wait_for("joined fleet relay", 30)
        # at real time the flight out lasts seconds: the kill lands before the broadcast even when this test's
        # reading of the line is slow (a loaded machine; at 4x the scout had broadcast by then)
        scout = aeroexec("run", str(MISSIONS / "relay_scout.py"), "--name", "scout", "--output",
                         str(tmp_path / "scout"), "--speed", "1", *common, cwd=tmp_path)
        scouting = Output(scout)
        scouting.wait_for("activated GO_TO_POINT", 60)  # on its way out, the message not sent
        scout.kill()
        scout.wait(10)
        assert "message_sent" not in scouting.text
        heard.wait_for("fleet_drone_silent: scout", 30)
        resumed = aeroexec("run", "--resume", str(tmp_path / "scout"), "--plain", "--speed", "4", cwd=tmp_path)
        back, _ = resumed.communicate(timeout=hang_guard(120))
        carrier.wait(hang_guard(120))
    finally:
        stop(*(p for p in (carrier, scout, resumed) if p is not None))
    assert resumed.returncode == 0, back[-3000:]
    assert "scout joined fleet relay" in back and "message_sent BROADCAST_MESSAGE: to carrier: area clear" in back
    assert carrier.returncode == 0, heard.text[-3000:]
    text = heard.text
    assert text.index("fleet_drone_silent: scout") < text.index("fleet_drone_heard: scout is heard again")
    assert text.count("message_received: from scout: area clear") == 1
    with Journal(tmp_path / "scout") as journal:
        sent = journal.rows("SELECT count(*) FROM events WHERE kind = 'message_sent'")[0][0]
        meta = journal.meta()
    assert sent == 1 and meta["spec"]["fleet"]["name"] == "scout" and "token" not in meta["spec"]["fleet"]
    assert meta["spec"]["fleet"]["credentials"] == str(credentials.resolve())
    assert resume_spec(tmp_path / "scout").fleet.trust == (("code", 2),)  # the resumed drone keeps its --trust
