"""Where a bench's figures were measured: the commit of the code and the machine's load, said beside every table a
bench writes into the README (which figures come from which code, under what load)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def commit() -> str:
    """The short hash of the checked-out commit, with ``+ changes`` when files other than the README and the pages of
    docs/performance differ from it (those are what the benches rewrite)."""
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              check=True).stdout.strip()
        changed = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".",
                                  ":(exclude)README.md", ":(exclude)docs/performance"], cwd=ROOT,
                                 capture_output=True, text=True,
                                 check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "(not a git checkout)"
    return f"{head} + uncommitted changes" if changed else head


def load() -> float:
    """The load average over the last minute."""
    return os.getloadavg()[0]


def measured_at(began: float) -> str:
    """``commit X, load average A when it began and B when it ended``."""
    return f"commit {commit()}, load average {began:.1f} when it began and {load():.1f} when it ended"
