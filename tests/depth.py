"""How many generated cases the property tests draw: a default sized for every run (the suite stays under
10 minutes), ``AEROEXEC_TEST_DEPTH=N`` multiplies it for a deeper run (``AEROEXEC_TEST_DEPTH=10 python -m
pytest tests/trees`` before a release)."""

from __future__ import annotations

import os


def examples(default: int) -> int:
    """``default`` generated cases, times ``$AEROEXEC_TEST_DEPTH`` (1 when unset)."""
    try:
        depth = float(os.environ.get("AEROEXEC_TEST_DEPTH", "1"))
    except ValueError:
        raise SystemExit(f"AEROEXEC_TEST_DEPTH must be a number, not {os.environ['AEROEXEC_TEST_DEPTH']!r}") from None
    return max(1, round(default * depth))
