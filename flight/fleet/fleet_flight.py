"""A fleet in one process: one :class:`~aeroexec.flight.session.FlightSession` per drone (its own catalog,
plugins, event log, ``.btlog`` and run status), in one world and airspace, ticked in lockstep on one simulated
clock, linked over the process's Zenoh node.

Each period ticks every engine, serves every Python mission until it waits, steps the end of every flight that
is ending, then exchanges the period's messages with the fleet (:meth:`FleetNode.exchange
<aeroexec.fleet.node.FleetNode.exchange>`: what each drone said goes out, and every drone hears it at its next
tick from the process's one table) and moves the clock one period on (paced to ``speed`` times real time when
given: the clock's own pacing, as for one drone). A drone whose mission ended lands
(:class:`~aeroexec.flight.ending.FlightEnding`); Ctrl-C, SIGTERM, SIGHUP, :meth:`FleetFlight.stop` and the time
limit end every mission and land every drone; a second interrupt leaves them as they are. The run ends when every
flight has ended.
"""

from __future__ import annotations

import gc
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from aeroexec.engine.clock import SimulatedClock
from aeroexec.engine.errors import Problem
from aeroexec.engine.missions.bridge import RUNNING
from aeroexec.engine.missions.script import ScriptMission, fly_together
from aeroexec.flight.ending import FlightEnding
from aeroexec.flight.fleet.status import drone_status, write_status
from aeroexec.flight.robot import load_world, robot_choice, vehicle_config
from aeroexec.flight.run_status import FlightOutcome
from aeroexec.flight.session import FlightSession
from aeroexec.flight.spec import FleetJoin, FlightError, FlightSpec
from aeroexec.flight.surfaces import Surfaces, serve_console

logger = logging.getLogger(__name__)

HAND_OVER = 0.0002  # wall seconds between two looks at missions still computing
STALL_WARNING = 30.0  # wall seconds of missions computing before saying so
#: The collector's youngest generation while a fleet flies in the command's own process: a collection every this many
#: objects made and kept (the default, 700, collected every few periods of a fleet of 100: ~2.5 % of its CPU, the
#: full passes it sets off included; at 10,000, ~0.5 %).
YOUNG_GENERATION = 10_000


@dataclass
class Member:
    """One drone of the fleet: its session and the end of its flight."""

    name: str
    session: FlightSession
    ending: FlightEnding | None = None
    ended: bool = False
    faults: list[str] = field(default_factory=list)

    @property
    def engine(self) -> Any:
        return self.session.engine

    @property
    def link(self) -> Any:
        return self.session.link


class FleetFlight:
    """The drones of a fleet flown in this process. ``drones`` are the fleet file's drone records (name, mission,
    home, seed, share); ``base`` is the flight every drone shares (robot kind, catalog, plugins, world, time
    limit; its ``mission`` is ignored); each drone's files go to ``output/<drone>/``. ``world`` overrides the
    base's world file. ``everyone``: the names of every drone of the world when other worker processes fly
    some of them in lockstep (:meth:`FleetNode.lockstep <aeroexec.fleet.node.FleetNode.lockstep>`)."""

    def __init__(self, node: Any, drones: list[Any], base: FlightSpec, *, output: Path, speed: float | None = None,
                 world: Any = None, telemetry_rate: float = 5.0, remote_questions: bool = False,
                 everyone: tuple[str, ...] | None = None,
                 notify: Callable[[str], None] = logger.warning,
                 report: Callable[[Problem], None] = lambda problem: logger.warning("%s", problem),
                 recording: str | None = None) -> None:
        self.node, self.drones, self.base, self.output = node, drones, base, Path(output)
        self.telemetry_rate, self.remote_questions = telemetry_rate, remote_questions
        self.notify, self.report = notify, report
        self.clock = SimulatedClock(speed=speed)  # one simulated time for every drone, paced when speed is given
        self.world = world  # None: the base spec's world file (or the robot kind's, or the built-in field)
        self.everyone = everyone  # the drones flown in this world: these and those of the other workers
        self.members: list[Member] = []
        self.surfaces = Surfaces()
        self._stop = threading.Event()
        self._how = "stop"
        self._over = False  # every flight of the fleet has ended
        self.time: dict[str, float] = {}  # how long the flight took: simulated, wall and CPU seconds
        self.recording_path = recording  # an MCAP file recording every drone while flying (None: none)
        self.recording: Any = None
        self._closed = False

    @property
    def engines(self) -> dict[str, Any]:
        """The engines by drone name (for a console or a view that shows several)."""
        return {m.name: m.engine for m in self.members}

    def open(self) -> FleetFlight:
        """Set every drone's flight up; FlightError (every session closed) when one cannot fly."""
        try:
            self._open()
        except BaseException:
            self.close()
            raise
        return self

    def _open(self) -> None:
        from aeroexec.drones.sim import Airspace

        base = self.base
        choice = robot_choice(base.robot)
        if self.world is None:
            self.world = load_world(choice.world_file(base.world), home=base.home)
        self.node.driven = True  # the exchange is at the end of each period
        # drones of processes of their own are not in this world; the other workers' are
        flying = frozenset(self.everyone if self.everyone is not None else (d.name for d in self.drones))
        where = self.node.table.where
        airspace = Airspace(lambda: {name: p for name, p in where.items() if name in flying})
        if self.recording_path is not None:  # before any drone: a file that cannot be written is refused first
            self.recording = open_recording(self.recording_path)
        for drone in self.drones:
            vehicle = str(drone.vehicle) if drone.vehicle is not None else base.vehicle  # its own, or the fleet's
            robot = self._robot(choice, drone, vehicle)
            if hasattr(robot, "join"):
                robot.join(airspace, drone.name)
            spec = replace(base, mission=Path(drone.mission), seed=drone.seed, output=str(self.output / drone.name),
                           vehicle=vehicle, log=None, web=None, groot=None, register=False,
                           remote_questions=self.remote_questions,
                           fleet=FleetJoin(self.node.fleet, drone.name, share=tuple(drone.share),
                                           telemetry_rate=self.telemetry_rate))
            session = FlightSession(spec, notify=lambda text: None, report=self.report, clock=self.clock,
                                    robot=robot, world=self.world, fleet_node=self.node)
            self.members.append(Member(drone.name, session))
            session.open()
            if self.recording is not None:
                self.recording.attach(session.flight_log, Path(drone.mission))

    def _robot(self, choice: Any, drone: Any, vehicle: str | None) -> Any:
        if choice.kind is None:
            from aeroexec.drones.sim import SimConfig, SimulatedDrone

            profile = vehicle_config(vehicle)  # its vehicle profile's figures, from its home
            config = replace(profile, start=drone.home) if profile is not None else SimConfig(start=drone.home)
            return SimulatedDrone(self.world, seed=drone.seed, config=config)
        if tuple(drone.home) != (0.0, 0.0):
            raise FlightError(f"{drone.name}: a {choice.kind.name} starts where its kind puts it; home: is for "
                              f"drones", usage=True)
        return choice.kind.simulator(self.world, drone.seed)

    def serve_console(self, port: int, host: str = "127.0.0.1") -> None:
        """The web console of every drone, on one map."""
        files = {m.name: m.session.spec.mission for m in self.members if m.session.tree is None}
        self.surfaces.add(serve_console(self.engines, self.world, files, port=port, host=host, notify=self.notify))

    def stop(self, how: str = "stop") -> None:
        """End every mission at the next period and land every drone (another thread may call it); ``how`` names
        who asked, in the event logs."""
        self._how = how
        self._stop.set()

    # -- the flight ---------------------------------------------------------------------------------
    def fly(self, max_time: float | None = None) -> dict[str, FlightOutcome]:
        """Fly every mission, then end every flight; each drone's outcome. Call it from the thread that may get
        KeyboardInterrupt (Ctrl-C, or SIGTERM/SIGHUP through :mod:`aeroexec.flight.signals`)."""
        max_time = self.base.max_time if max_time is None else max_time
        if self.clock.speed is not None:
            self.clock.pace_from_now()  # setting many drones up takes a while: real time starts now
        self._start_missions()
        started, cpu = time.monotonic(), time.process_time()
        if gc.get_freeze_count():
            # the command's own process froze what its start made (cli.main): what setting every drone up made
            # lives as long too, and the collector's full passes no longer walk it every few periods (500 drones:
            # ~1.4 s of a 10 s flight's CPU); a process that embeds the fleet keeps its collector as it is. What a
            # period makes and keeps is collected every YOUNG_GENERATION objects, not every 700 (a few periods)
            gc.freeze()
            thresholds = gc.get_threshold()
            if thresholds[0]:  # 0: automatic collection is off, and stays so
                gc.set_threshold(max(thresholds[0], YOUNG_GENERATION), *thresholds[1:])
        else:
            thresholds = None
        try:
            try:
                self._loop(max_time)
            except KeyboardInterrupt as interrupt:
                self._interrupt(getattr(interrupt, "signal_name", "Ctrl-C"))
                self._loop(float("inf"))
        except KeyboardInterrupt:
            self.notify("interrupted again: leaving the drones as they are")
            for m in self.members:
                if not m.ended:
                    m.ended = True
                    m.faults = ["the operator interrupted the end of the flight: the drone was left as it was"]
        finally:
            if thresholds is not None:
                gc.set_threshold(*thresholds)
        self.time = {"simulated": self.clock.now(), "wall": time.monotonic() - started,
                     "cpu": time.process_time() - cpu, "workers": 1}
        outcomes = {m.name: m.session.finish(m.faults) for m in self.members}
        self._write_status(outcomes)
        self.close()
        return outcomes

    def _start_missions(self) -> None:
        """Start every drone's mission. Drones that name one Aerostack2 script fly it together: it runs once and
        drives each of them by its namespace (:func:`~aeroexec.engine.missions.script.fly_together`)."""
        scripts: dict[Path, list[Member]] = {}
        for m in self.members:
            if isinstance(m.session.mission, ScriptMission):
                scripts.setdefault(m.session.mission.path.resolve(), []).append(m)
        for group in scripts.values():
            fly_together({m.name: m.engine for m in group}, group[0].session.mission, group[0].session.spec.name)
        for m in self.members:
            if not isinstance(m.session.mission, ScriptMission):
                m.session.start_mission()

    def _interrupt(self, how: str) -> None:
        self.notify(f"interrupted by the operator ({how}): every drone aborts and lands "
                    f"({how} again leaves them as they are)")
        for m in self.members:
            if m.ending is None:
                m.session.interrupted(how)

    def _loop(self, max_time: float) -> None:
        period = self.members[0].engine.period if self.members else 0.05
        flying = not self._over
        while flying:
            if self._stop.is_set():
                self._stop.clear()
                self._interrupt(self._how)
            now = self.clock.now()
            if now >= max_time:
                for m in self.members:
                    if m.ending is None and not m.session.mission_done:
                        m.session.time_limit()
            self._period()
            # in lockstep the fleet flies on until every worker's flights have ended, at the same period in each
            flying = self.node.exchange(now, all(m.ended for m in self.members))
            self._over = not flying
            self.clock.sleep_until(now + period, self._stop)

    def _period(self) -> None:
        members = self.members
        for m in members:
            m.session.engine.tick()  # a drone whose flight ended is still heard (telemetry) and still hears
        self._serve([m for m in members if m.ending is None])
        for m in members:
            ending = m.ending
            if ending is None:
                if not m.session.mission_done:
                    continue
                ending = m.ending = m.session.ending()
            if ending is not None and not m.ended and ending.step():
                m.ended, m.faults = True, ending.faults

    def _serve(self, members: list[Member]) -> None:
        """Serve every Python mission until each waits on its engine (lockstep, as ``Engine.step``); the
        mission threads run side by side meanwhile, so N missions cost about one hand-over, not N."""
        warned_at = None
        while True:
            waiting = []
            for m in members:  # a script flying several drones may be waiting on any of them
                engine = m.session.engine
                bridge = engine.bridge
                bridge.serve(lockstep=False)  # what is queued now; returns when the queue is empty
                if bridge.state == RUNNING and not engine.supervisor.paused and not engine.stopped:
                    waiting.append(m)
            if not waiting:
                return
            if warned_at is None:
                warned_at = time.monotonic() + STALL_WARNING
            time.sleep(HAND_OVER)
            if time.monotonic() > warned_at:
                logger.warning("the missions of %s have been busy for %.0f s of wall time without calling their "
                               "engines; simulated time waits for them", ", ".join(m.name for m in waiting),
                               STALL_WARNING)
                warned_at = time.monotonic() + STALL_WARNING

    def _write_status(self, outcomes: dict[str, FlightOutcome]) -> None:
        write_status(self.output, self.node.fleet, {name: drone_status(o) for name, o in outcomes.items()},
                     {"time": self.time})

    def close(self) -> None:
        """Close every drone's session and the surfaces (idempotent, never hangs)."""
        if self._closed:
            return
        self._closed = True
        self.surfaces.close()
        for m in self.members:
            m.session.close()
        if self.recording is not None:  # once every log is closed: their last lines are in it
            try:
                self.recording.close()
            except Exception:  # never keeps the fleet from closing
                logger.exception("closing the recording failed")


def open_recording(path: str) -> Any:
    """The fleet's MCAP recording (``flight/recording/live.py``); FlightError when the file cannot be written."""
    from aeroexec.flight.recording.live import LiveRecording
    from aeroexec.flight.recording.mcap_file import McapFile

    try:
        return LiveRecording([McapFile(path)], path)
    except OSError as error:
        raise FlightError(f"the recording {path} cannot be written: {error.strerror or error}", usage=True) from None


__all__ = ["FleetFlight", "Member"]
