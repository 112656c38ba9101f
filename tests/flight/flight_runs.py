"""Runs of ``aeroexec`` in a subprocess for the tests of how flights end: output read as it comes, signals sent
at a chosen line, the event log read back."""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from patience import hang_guard

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"
RUN_S = 120.0  # s, wall: longest any run below may take



class Command:
    """``aeroexec ARGS`` in a subprocess; stdout and stderr read line by line as they come."""

    def __init__(self, cwd: Path, *args: str) -> None:
        self.process = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", *args],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd)
        self.lines: queue.Queue[str] = queue.Queue()
        self.out: list[str] = []
        self.err: list[str] = []
        self._readers = [threading.Thread(target=self._read, args=(self.process.stdout, self.out), daemon=True),
                         threading.Thread(target=self._read, args=(self.process.stderr, self.err), daemon=True)]
        for reader in self._readers:
            reader.start()

    def _read(self, stream, into: list[str]) -> None:
        for line in stream:
            into.append(line.rstrip("\n"))
            self.lines.put(line.rstrip("\n"))

    def wait_for(self, text: str, timeout: float = 60.0) -> str:
        """The first line (stdout or stderr) holding ``text``; fails the test when none comes in time."""
        deadline = time.monotonic() + hang_guard(timeout)
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.1)
            except queue.Empty:
                if self.process.poll() is not None and self.lines.empty():
                    break
                continue
            if text in line:
                return line
        pytest.fail(f"no line with {text!r}:\n" + "\n".join(self.out[-20:] + self.err[-20:]))

    def signal(self, number: int) -> None:
        self.process.send_signal(number)

    def finish(self, timeout: float = RUN_S) -> tuple[int, str, str]:
        """Exit status, stdout and stderr once the process ended."""
        try:
            self.process.wait(timeout=hang_guard(timeout))
        except subprocess.TimeoutExpired:
            self.process.kill()
            pytest.fail("the command did not end:\n" + "\n".join(self.out[-20:] + self.err[-20:]))
        for reader in self._readers:
            reader.join(timeout=10)
        return self.process.returncode, "\n".join(self.out), "\n".join(self.err)


def read_log(path: Path) -> list[dict]:
    """Every line of an event log, each parsed (a line that is not whole JSON fails the test)."""
    records = []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        try:
            records.append(json.loads(line))
        except ValueError:
            pytest.fail(f"{path}:{number} is not a whole record: {line[:200]!r}")
    return records


def ended(records: list[dict]) -> dict:
    """The ``run_ended`` record of a log."""
    found = [r for r in records if r["kind"] == "run_ended"]
    assert len(found) == 1, [r["kind"] for r in records[-10:]]
    return found[0]


def landed(records: list[dict]) -> bool:
    """Whether the log's last drone state says on the ground, disarmed."""
    state = [r for r in records if r["kind"] == "state"][-1]
    return state["landed_state"] == "on_ground" and not state["armed"]
