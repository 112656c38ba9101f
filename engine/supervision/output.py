"""Where a run's files go: the one place that decides the output folder (``--output DIR``, else
``aeroexec_output/<date-time>`` in the working directory, made unique when two runs start in the same second)."""

from __future__ import annotations

import time
from pathlib import Path

DEFAULT_BASE = Path("aeroexec_output")


def choose_output_folder(explicit: str | Path | None = None, base: str | Path = DEFAULT_BASE) -> Path:
    """The run's output folder: ``explicit`` when given (not created), else a new ``base/<date-time>[-N]``, created
    here so that two runs started in the same second in the same folder never share one."""
    if explicit is not None:
        return Path(explicit)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    n = 1
    while True:
        folder = Path(base) / (stamp if n == 1 else f"{stamp}-{n}")
        try:
            folder.mkdir(parents=True)
        except FileExistsError:
            n += 1
            continue
        except OSError:
            return folder  # the caller's own creation says why it cannot be made
        return folder
