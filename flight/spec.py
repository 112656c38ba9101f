"""What a flight is made of, as plain records: the mission file, the robot and its adapter, the world, the
catalog and plugins, the clock's pacing, the outputs and the control surfaces (:class:`FlightSpec`), and, for a
drone of a fleet, how it joins (:class:`FleetJoin`). ``aeroexec run`` builds one from its arguments; an embedder
builds one in code."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from aeroexec.flight.errors import FlightError  # here too: its old place

LINK_GRACE = 30.0  # s of engine time the end of a flight keeps trying to reach a drone whose link is down
READY_TIMEOUT = 180.0  # s a MAVSDK vehicle may take to be ready (ArduCopter SITL: ~45 s from boot)
MAX_TIME = 1800.0  # s of mission time a flight is given by default


@dataclass(frozen=True)
class FleetJoin:
    """A drone joining a fleet from its own process (``aeroexec run --fleet``)."""

    fleet: str
    name: str
    connect: tuple[str, ...] = ()
    token: str | None = None
    share: tuple[str, ...] = ()
    telemetry_rate: float = 5.0  # Hz the drone's telemetry goes to the fleet
    credentials: str | None = None  # its identity: a folder holding <name>.pem, <name>.key, ca.pem, or the .pem
    trust: tuple[tuple[str, int], ...] = ()  # (predicate, k): believe a mate's belief of it once k members say it


@dataclass
class FlightSpec:
    """One flight, as an operator asks for it. Paths are as given (relative to the working folder)."""

    mission: Path
    robot: str = "drone"  # a robot kind (``aeroexec.robots`` entry points add kinds)
    drone: str = "sim"  # sim | mavsdk:URL | NAME:ADDRESS (an ``aeroexec.drones`` adapter)
    world: str | None = None  # the world file (None: the robot kind's, else the built-in field)
    home: tuple[float, float, float | None] | None = None  # --home LAT,LON[,ALT]: the world's home (take-off point)
    catalog: str | None = None  # the behavior catalog file (None: the robot kind's)
    vehicle: str | None = None  # the vehicle profile file (``--vehicle``; None: the simulated multicopter's figures)
    library: tuple[str, ...] = ()  # behavior providers ``module:attribute``
    processes: tuple[str, ...] = ()  # capability process providers ``module:attribute``
    updaters: tuple[str, ...] = ()  # belief updater providers ``module:attribute``
    speed: float | None = None  # simulated time this many times real time (None: as fast as possible)
    seed: int = 0
    max_time: float = MAX_TIME
    output: str | None = None  # the output folder (None: aeroexec_output/<date-time>)
    log: str | None = None  # the event log (None: events.jsonl in the output folder)
    answers: str | None = None  # the operator's answers (YAML); None: ask (remote or terminal) or default
    remote_questions: bool = False  # questions wait for the live view, the console or ``aeroexec ctl answer``
    interactive: bool = False  # questions may be asked at this terminal
    web: int | None = None  # serve the web console on this port (0: a free one); None: no console
    web_host: str = "127.0.0.1"
    groot: int | None = None  # serve Groot2 on this port; None: no Groot2
    mcap: str | None = None  # write an MCAP recording of the flight to this file while flying; None: none
    foxglove: int | None = None  # serve the recording's topics to Foxglove on this port (0: a free one); None: not
    link_grace: float = LINK_GRACE
    ready_timeout: float = READY_TIMEOUT
    fleet: FleetJoin | None = None
    register: bool = True  # list the run in the user's runtime folder (``aeroexec ctl`` finds it)
    rules: tuple[str, ...] = ()  # rules files of the belief memory (derived beliefs)
    safety_rules: tuple[str, ...] = ()  # safety rules files (the catalog's and the mission's rules are watched too)
    beliefs: tuple[str, ...] = ()  # beliefs the operator gives at launch (--event, --alert), added as it starts
    resume: bool = False  # go on with the interrupted run in ``output`` from where its journal says it stopped
    journal: bool = True  # keep the flight journal (journal.sqlite in the output folder)
    script_args: tuple[str, ...] = ()  # a script's own arguments (``aeroexec run script.py -- ARGS``): its sys.argv[1:]

    @property
    def name(self) -> str:
        """The mission's name in lines, logs and the run list: its file name."""
        return Path(self.mission).name

    @property
    def simulated(self) -> bool:
        return self.drone == "sim"


__all__ = ["LINK_GRACE", "MAX_TIME", "READY_TIMEOUT", "FleetJoin", "FlightError", "FlightSpec"]
