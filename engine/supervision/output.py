"""Where a run's files go: the one place that decides the output folder (``--output DIR``, else
``aeroexec_output/<date-time>`` in the working directory, made unique when two runs start in the same second)."""

from __future__ import annotations

import time
from pathlib import Path

DEFAULT_BASE = Path("aeroexec_output")


def choose_output_folder(explicit: str | Path | None = None, base: str | Path = DEFAULT_BASE) -> Path:
    """The run's output folder (not created): ``explicit`` when given, else a new ``base/<date-time>[-N]``."""
    if explicit is not None:
        return Path(explicit)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    folder = Path(base) / stamp
    n = 2
    while folder.exists():
        folder = Path(base) / f"{stamp}-{n}"
        n += 1
    return folder
