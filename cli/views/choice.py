"""Which view a run shows: the live view for a person at a terminal, else its events as plain lines (a module of
its own, so that a run without the live view never imports it: :mod:`aeroexec.cli.views.live`)."""

from __future__ import annotations

import sys

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


def wanted(args: Any) -> bool:
    """The live view is for a person at a terminal: not with --plain or --quiet, nor when stdout is no TTY."""
    return not getattr(args, "plain", False) and not getattr(args, "quiet", False) and sys.stdout.isatty()
