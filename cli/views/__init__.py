"""The terminal views of a run: the live view of one drone (mission, behaviors, beliefs, events, keys) and the
one-line-per-drone view of a fleet."""

from __future__ import annotations

import sys

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


def wanted(args: Any) -> bool:
    """The live view is for a person at a terminal: not with --plain or --quiet, nor when stdout is no TTY (here, so
    that a run without it never imports the view: :mod:`aeroexec.cli.views.live`)."""
    return not getattr(args, "plain", False) and not getattr(args, "quiet", False) and sys.stdout.isatty()
