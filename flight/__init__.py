"""The flight: one place where a flight is set up, flown and ended, between the engine and its users
(``aeroexec run``, each drone of ``aeroexec fleet``, the console's replay, embedders): the robot and its adapter,
catalog, plugins and updaters, world, clock and pacing, the run's files (event log, ``.btlog``, run status,
output folder), the control surfaces (control socket, web console, Groot2), and the end of the flight whatever
ends it (the mission, the time limit, an abort, Ctrl-C, SIGTERM, SIGHUP, a lost link, a full disk).

The names below are imported when first used, so a command that needs one module of the package (``aeroexec
verify`` reads missions with :mod:`aeroexec.flight.missions`) does not load the others.
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["FleetFlight", "FleetJoin", "FleetSession", "FlightError", "FlightOutcome", "FlightSession", "FlightSpec",
           "Interrupted", "WorkerFleet", "ending_signals", "fleet_exit_status"]
__getattr__ = lazy_names(__name__, {"FleetFlight": "fleet.fleet_flight", "fleet_exit_status": "fleet.status",
                                    "FleetSession": "fleet.session",
                                    "WorkerFleet": "fleet.workers", "FlightOutcome": "run_status",
                                    "FlightSession": "session", "Interrupted": "signals", "ending_signals": "signals",
                                    "FleetJoin": "spec", "FlightError": "spec", "FlightSpec": "spec"})

if TYPE_CHECKING:
    from aeroexec.flight.fleet.fleet_flight import FleetFlight
    from aeroexec.flight.fleet.session import FleetSession
    from aeroexec.flight.fleet.status import fleet_exit_status
    from aeroexec.flight.fleet.workers import WorkerFleet
    from aeroexec.flight.run_status import FlightOutcome
    from aeroexec.flight.session import FlightSession
    from aeroexec.flight.signals import Interrupted, ending_signals
    from aeroexec.flight.spec import FleetJoin, FlightError, FlightSpec
