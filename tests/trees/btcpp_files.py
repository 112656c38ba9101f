"""Reading what behaviortreepy's FileLogger (BehaviorTree.CPP's FileLogger2) wrote: it writes from its own thread
every 10 ms, and closing it drops what is still queued, so wait for the file to settle before closing it."""

from __future__ import annotations

import time
from pathlib import Path


def settle(path: Path, header: int, quiet: float = 0.05, limit: float = 5.0) -> None:
    """Wait until transitions follow the ``header`` bytes and the file has not grown for ``quiet`` seconds."""
    size, still, start = -1, time.monotonic(), time.monotonic()
    while time.monotonic() - start < limit:
        now = path.stat().st_size
        if now != size:
            size, still = now, time.monotonic()
        elif now > header and time.monotonic() - still >= quiet:
            return
        time.sleep(0.005)
