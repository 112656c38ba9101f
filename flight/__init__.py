"""The flight: one place where a flight is set up, flown and ended, between the engine and its users
(``aeroexec run``, each drone of ``aeroexec fleet``, the console's replay, embedders): the robot and its adapter,
catalog, plugins and updaters, world, clock and pacing, the run's files (event log, ``.btlog``, run status,
output folder), the control surfaces (control socket, web console, Groot2), and the end of the flight whatever
ends it (the mission, the time limit, an abort, Ctrl-C, SIGTERM, SIGHUP, a lost link, a full disk).

The names below are imported when first used, so a command that needs one module of the package (``aeroexec
verify`` reads missions with :mod:`aeroexec.flight.missions`) does not load the others.
"""

from __future__ import annotations

import importlib
from typing import Any

_PUBLIC = {
    "FleetFlight": "fleet", "fleet_exit_status": "fleet", "WorkerFleet": "fleet.workers",
    "FlightOutcome": "run_status", "FlightSession": "session",
    "Interrupted": "signals", "ending_signals": "signals",
    "FleetJoin": "spec", "FlightError": "spec", "FlightSpec": "spec",
}


def __getattr__(name: str) -> Any:
    if name not in _PUBLIC:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_PUBLIC[name]}"), name)


__all__ = sorted(_PUBLIC)
