"""A fleet flown from one fleet file: every drone one :class:`~aeroexec.flight.session.FlightSession`, in one world
and on one simulated time, linked over the fleet's Zenoh router.

- :mod:`~aeroexec.flight.fleet.session`: the fleet from set-up to its end, as a flight session is one drone's: output
  folder, token, the fleet's router or a link to it, ``fleet.json``, the drones here or in workers
  (:class:`FleetSession`);
- :mod:`~aeroexec.flight.fleet.fleet_flight`: the drones of one process, ticked in lockstep (:class:`FleetFlight`);
- :mod:`~aeroexec.flight.fleet.workers`: the drones spread over worker processes, one per core, each a
  :class:`FleetFlight` of its share, in lockstep with the others through the router (:class:`WorkerFleet`);
- :mod:`~aeroexec.flight.fleet.worker`: one worker process's side;
- :mod:`~aeroexec.flight.fleet.status`: how the fleet and each drone ended (``fleet_status.json``).

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["FleetFlight", "FleetSession", "Member", "STATUS_FILE", "drone_status", "event_line", "fleet_exit_status",
           "summary_line", "write_status"]
__getattr__ = lazy_names(__name__, {"FleetFlight": "fleet_flight", "Member": "fleet_flight", "FleetSession": "session",
                                    "STATUS_FILE": "status",
                                    "drone_status": "status", "event_line": "status", "fleet_exit_status": "status",
                                    "summary_line": "status", "write_status": "status"})

if TYPE_CHECKING:
    from aeroexec.flight.fleet.fleet_flight import FleetFlight, Member
    from aeroexec.flight.fleet.session import FleetSession
    from aeroexec.flight.fleet.status import (
        STATUS_FILE,
        drone_status,
        event_line,
        fleet_exit_status,
        summary_line,
        write_status,
    )
