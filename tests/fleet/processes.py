"""Helpers of the fleet tests that start aeroexec in processes of its own."""

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from patience import hang_guard

MISSIONS = Path(__file__).resolve().parents[2] / "missions"
TOKEN = "t0k3n"
HOVER = '''"""Take off, hover until someone says "go home" (or 600 s), land."""
import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=2)
    waited = 0
    while not api.true_belief('message(?D, "go home")') and waited < 600:
        api.wait(0.5)
        waited += 0.5
    api.execute_behavior("LAND")
'''  # a mission that flies until the operator ends it


def aeroexec(*args: str, cwd: Path) -> subprocess.Popen:
    env = {**os.environ, "AEROEXEC_FLEET_TOKEN": TOKEN}
    return subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", *args], cwd=cwd, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)


def stop(*processes: subprocess.Popen) -> None:
    for process in processes:
        if process.poll() is None:
            process.kill()
            process.wait(10)


def wait_for_lines(process: subprocess.Popen, texts: list[tuple[str, ...]], timeout: float) -> list[str]:
    """The process's output lines up to the one where, for each tuple of ``texts``, a line holding every text of it
    has been seen (e.g. ``[("d1 |", "drone_takeoff_complete"), ("d2 |", "drone_takeoff_complete")]``); kills it
    when they do not all come in time."""
    lines: list[str] = []
    found = threading.Event()
    waiting = list(texts)

    def read() -> None:
        for line in process.stdout:
            lines.append(line)
            waiting[:] = [t for t in waiting if not all(part in line for part in t)]
            if not waiting:
                found.set()
                return

    threading.Thread(target=read, daemon=True).start()
    if not found.wait(timeout):
        process.kill()
        raise AssertionError(f"{waiting!r} not seen in {timeout:g} s: {''.join(lines)[-3000:]}")
    return lines


def wait_for_line(process: subprocess.Popen, text: str, timeout: float) -> list[str]:
    """The process's output lines up to the first holding ``text``; kills it when none comes in time."""
    lines: list[str] = []
    found = threading.Event()

    def read() -> None:
        for line in process.stdout:
            lines.append(line)
            if text in line:
                found.set()
                return

    threading.Thread(target=read, daemon=True).start()
    if not found.wait(hang_guard(timeout)):
        process.kill()
        raise AssertionError(f"{text!r} not seen in {timeout:g} s: {''.join(lines)[-3000:]}")
    return lines


class Output:
    """Every output line of a process, read as it comes; :meth:`wait` for what a test expects of them."""

    def __init__(self, process: subprocess.Popen) -> None:
        self.process, self.lines = process, []
        self.times: list[float] = []  # time.monotonic() when each line came
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in self.process.stdout:
            with self._changed:
                self.lines.append(line)
                self.times.append(time.monotonic())
                self._changed.notify_all()
        with self._changed:
            self.lines.append("")  # the end
            self._changed.notify_all()

    def wait(self, done, what: str, timeout: float) -> list[str]:
        """The lines once ``done(lines)`` holds; kills the process when it does not hold within ``timeout``."""
        with self._changed:
            if self._changed.wait_for(lambda: done(self.lines) or self.lines[-1:] == [""], timeout) and done(
                    self.lines):
                return list(self.lines)
        self.process.kill()
        raise AssertionError(f"{what}: not seen in {timeout:g} s: {''.join(self.lines)[-3000:]}")

    @property
    def text(self) -> str:
        return "".join(self.lines)
