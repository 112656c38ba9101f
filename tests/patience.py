"""How long the tests wait before calling something hung: the one place that scales every hang guard.

A test waits for an event (a line, a file, a status); the seconds it gives that event are only a guard against a
real hang, never a measure of speed. On a loaded machine (other processes keeping the cores busy, CI) everything
takes longer, so :func:`hang_guard` stretches each guard by the machine's load per core (at least 1) and, in CI
(``CI=true``), by at least 3. ``AEROEXEC_TEST_PATIENCE=N`` sets the factor by hand.
"""

from __future__ import annotations

import os

#: The factor in CI at the least: a CI machine is shared and its load comes and goes within a test.
CI_FACTOR = 3.0
#: The factor never goes beyond this: a real hang must still end the test.
MAX_FACTOR = 10.0


def patience() -> float:
    """The factor every hang guard is multiplied by now."""
    chosen = os.environ.get("AEROEXEC_TEST_PATIENCE", "").strip()
    if chosen:
        return max(1.0, float(chosen))
    try:
        load = os.getloadavg()[0] / (os.cpu_count() or 1)
    except OSError:
        load = 1.0
    ci = CI_FACTOR if os.environ.get("CI", "").lower() in ("true", "1", "yes") else 1.0
    return min(MAX_FACTOR, max(1.0, ci, load))


def hang_guard(seconds: float) -> float:
    """``seconds`` (what an idle machine needs, with a margin) stretched for this machine's load: the time after
    which a wait for an event fails the test as hung."""
    return seconds * patience()
