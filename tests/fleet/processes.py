"""Helpers of the fleet tests that start aeroexec in processes of its own."""

import os
import subprocess
import sys
import threading
from pathlib import Path

from patience import hang_guard

MISSIONS = Path(__file__).resolve().parents[2] / "missions"
TOKEN = "t0k3n"


def aeroexec(*args: str, cwd: Path) -> subprocess.Popen:
    env = {**os.environ, "AEROEXEC_FLEET_TOKEN": TOKEN}
    return subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", *args], cwd=cwd, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)


def stop(*processes: subprocess.Popen) -> None:
    for process in processes:
        if process.poll() is None:
            process.kill()
            process.wait(10)


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
