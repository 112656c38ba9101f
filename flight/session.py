"""One flight of one robot, from set-up to its end: the robot kind and adapter, catalog, plugins and updaters,
the world, the clock and its pacing, the outputs (event log, ``.btlog``, control file), the control surfaces
(control socket, web console, Groot2), the mission, and the end of the flight (link grace, landing, disarm,
faults, how the run ended).

``aeroexec run`` flies one :class:`FlightSession`; each drone of ``aeroexec fleet`` is one, driven in lockstep
(:mod:`aeroexec.flight.fleet`); an embedder builds a :class:`~aeroexec.flight.spec.FlightSpec` and flies it::

    with FlightSession(FlightSpec(mission=Path("figure10.py"))) as session:
        outcome = session.fly()          # lands whatever ends it: the mission, the time limit, Ctrl-C, SIGTERM
    print(outcome.status.word, outcome.exit_status)
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from pathlib import Path

from aeroexec.drones.interface import CAMERA_NONE
from aeroexec.engine.catalog import BehaviorCatalog, CatalogError
from aeroexec.engine.clock import Clock, SimulatedClock, WallClock
from aeroexec.engine.engine import Engine  # loaded with the session, before the run lists itself as starting
from aeroexec.engine.errors import Problem
from aeroexec.engine.missions.bridge import DONE  # (engine.engine's import: loaded already)
from aeroexec.flight.control import ControlServer
from aeroexec.flight.ending import FlightEnding, end_flight
from aeroexec.flight.flight_log import FlightLogWriter, world_meta
from aeroexec.flight.journal import JournalError, JournalWriter, open_journal
from aeroexec.flight.journal.identity import FlightFile, flight_files, new_run_id
from aeroexec.flight.mission_changes import MissionChanges, contingency_handlers
from aeroexec.flight.missions import is_tree_document, load_mission, no_camera, watched_catalog
from aeroexec.flight.output import NO_SPACE, no_space, prepare_output
from aeroexec.flight.robot import (
    RobotChoice,
    flight_operator,
    load_world,
    make_engine,
    make_robot,
    robot_choice,
    vehicle_config,
    with_rule_files,
)
from aeroexec.flight.run_status import FAILED, FlightOutcome, flight_status, record_run_status
from aeroexec.flight.signals import interrupts_held
from aeroexec.flight.spec import FlightError, FlightSpec
from aeroexec.flight.surfaces import Surfaces, serve_console, serve_groot

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # a resume's records are imported only to resume a run
    from typing import Any

    from aeroexec.flight.journal.resumption import Resumption
    from aeroexec.trees import TreeDocument

logger = logging.getLogger(__name__)

CAMERA_WAIT = 3.0  # s (wall) a vehicle's camera may take to be heard (its heartbeat comes once a second)


class FlightSession:
    """One flight: :meth:`open` sets it up (raising :class:`FlightError` for anything the operator must fix,
    before anything moves), :meth:`fly` flies the mission and ends the flight whatever ends it, :meth:`close`
    releases everything (idempotent; after an error in :meth:`open` too).

    ``notify`` hears one-line messages for the operator (where the log goes, the console's URL, warnings),
    ``report`` each problem the mission's check finds. ``clock`` and ``robot`` are given by a fleet (one
    simulated time, drones in one airspace); alone, a session makes its own."""

    def __init__(self, spec: FlightSpec, *, notify: Callable[[str], None] = logger.warning,
                 report: Callable[[Problem], None] = lambda problem: logger.warning("%s", problem),
                 clock: Clock | None = None, robot: Any = None, world: Any = None, operator: Any = None,
                 fleet_node: Any = None) -> None:
        self.spec, self.notify, self.report = spec, notify, report
        self.clock, self.robot, self.world, self.operator = clock, robot, world, operator
        self.fleet_node = fleet_node  # a fleet's node in this process (the drone's link joins it)
        self.folder: Path | None = None
        self.catalog: BehaviorCatalog | None = None
        self.vehicle: Any = None  # the SimConfig of the --vehicle profile (None: the simulated multicopter's)
        self.mission: Callable[[], Any] | TreeDocument | None = None
        self.engine: Engine | None = None
        self.tree: Any = None  # the TreeMission of a tree mission
        self.changes: MissionChanges | None = None  # the changes of the running mission (engine.supervisor's)
        self.link: Any = None  # the fleet link
        self._joined: Any = None  # the fleet joined from this process alone (its session and node)
        self.flight_log: FlightLogWriter | None = None
        self.recording: Any = None  # the MCAP recording written while flying (--mcap)
        self.btlog: Any = None
        self.control: ControlServer | None = None
        self.journal: JournalWriter | None = None  # the flight journal (journal.sqlite)
        self.resumption: Resumption | None = None  # what a resumed run goes on from
        self.outcome: FlightOutcome | None = None
        self._surfaces = Surfaces()
        self._cancel = threading.Event()  # the start is given up (``ctl abort`` while starting)
        self._opened = self._closed = False
        self._mission_started_at: float | None = None

    # -- set-up -------------------------------------------------------------------------------------
    def __enter__(self) -> FlightSession:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def open(self) -> FlightSession:
        """Set the flight up; raises :class:`FlightError` (closing what was opened) when it cannot fly."""
        if self._opened:
            return self
        self._opened = True
        try:
            self._open()
        except BaseException:
            self.close()
            raise
        return self

    def _open(self) -> None:
        spec = self.spec
        self.folder = prepare_output(spec.output)
        log_path = Path(spec.log) if spec.log else self.folder / "events.jsonl"
        choice = robot_choice(spec.robot)
        world_path = choice.world_file(spec.world)
        if spec.resume:  # refused before anything is written (the journal, the event log) or flown
            from aeroexec.flight.journal.resume_point import resume_point  # here: only a resumed run reads them
            from aeroexec.flight.journal.resumption import Resumption

            try:
                self.resumption = Resumption(resume_point(self.folder))
                self.resumption.check(spec, world_path, log_path)
            except JournalError as error:
                raise FlightError(str(error)) from None
        start = self.resumption.point.time if self.resumption is not None else 0.0
        if spec.register:  # ctl finds the run from now on, while it starts
            self.control = ControlServer(None, self.folder, name=spec.name, register=spec.register,
                                         on_abort=self._cancel.set).start()
        try:
            self.catalog = with_rule_files(choice.catalog(spec.catalog), spec.rules)
        except CatalogError as error:
            raise FlightError("\n".join(str(p) for p in error.problems)) from None
        if self.world is None:
            self.world = load_world(world_path, default=spec.simulated or choice.kind is not None,
                                    mission=Path(spec.mission), home=spec.home)  # a plan's open field, --home
        if self.control is not None:
            self.control.starting = "checking its mission"
        self.vehicle = vehicle_config(spec.vehicle)  # --vehicle: the route, the simulator and the safety rules
        self.mission = load_mission(Path(spec.mission), self.catalog, self.world, self.report,
                                    verb="fly" if choice.kind is None else "run",  # a rover does not fly
                                    vehicle=self.vehicle, max_time=spec.max_time, script_args=spec.script_args)
        if self.resumption is not None and not is_tree_document(self.mission):
            self.resumption.check_program(Path(spec.mission))
        self.catalog = watched_catalog(Path(spec.mission), self.catalog, spec.safety_rules, self.world, self.report,
                                       self.vehicle)
        if self.robot is None:
            if self.control is not None:
                self.control.starting = "waiting for its vehicle"
            self.robot, simulated = make_robot(spec, choice, self.world, self.notify, self._cancel.is_set, start,
                                               self.vehicle)
            if self.resumption is not None:
                self.resumption.place(self.robot)
            self._check_camera()
        else:
            simulated = True
        if self._cancel.is_set():
            raise FlightError(f"{spec.name}: the start was aborted (aeroexec ctl abort)")
        self.engine = self._engine(choice, simulated, start)
        self.engine.period_guard = interrupts_held  # Ctrl-C, SIGTERM: between periods, never within one
        self.changes = MissionChanges(self)
        self.engine.supervisor.changes = self.changes
        if spec.fleet is not None or self.fleet_node is not None:
            self._join_fleet()
        if self.resumption is not None and is_tree_document(self.mission):  # refused before any output
            self.resumption.check_tree(self.mission, self.engine, spec.mission)
        run = self.resumption.run if self.resumption is not None else new_run_id()
        meta = {"mission": spec.name, "world": str(Path(world_path).resolve()) if world_path else None,
                "drone": spec.drone, "seed": spec.seed, "robot": spec.robot, "output": str(self.folder),
                "run": run, **world_meta(self.world)}
        if spec.fleet is not None:
            meta.update(fleet=spec.fleet.fleet, drone_name=spec.fleet.name)
        if spec.journal:
            self._open_journal(meta, flight_files(spec.mission, world_path, spec.catalog, spec.rules,
                                                  spec.safety_rules, spec.vehicle))
        if spec.mcap or spec.foxglove is not None:  # before the log: refused before anything is logged
            self._open_recording()
        try:
            self.flight_log = FlightLogWriter(self.engine, log_path, meta=meta,
                                              resumed=self.journal.segment if self.resumption else None)
        except OSError as error:
            if error.errno in NO_SPACE:
                raise no_space(self.folder, f"the event log cannot be written: {error.strerror}") from None
            raise FlightError(f"the event log {log_path} cannot be written: {error.strerror or error}",
                              usage=True) from None
        self.notify(f"event log: {log_path}")
        if self.recording is not None:
            self.recording.attach(self.flight_log, Path(spec.mission))
            if self.recording.path is not None:
                self.notify(f"recording: {self.recording.path}")
        if self.resumption is not None:  # once the logs listen: the resumed part says what it holds
            self.resumption.restore_beliefs(self.engine)
        self.engine.log.subscribe(self._warn_of_early_link_loss)
        if self.control is not None:
            self.control.attach(self.engine)
        if is_tree_document(self.mission):
            from aeroexec.trees.groot.btlog import BtlogWriter
            from aeroexec.trees.runtime.runner import TreeMission

            self.tree = TreeMission(self.mission, self.engine, name=spec.name)
            if self.resumption is not None:
                self.resumption.restore_tree(self.tree, self.spec.mission)
            self.btlog = BtlogWriter(self.tree, self.folder / "mission.btlog", self.catalog,
                                     append=self.resumption is not None)
            if self.journal is not None:
                self.journal.attach_tree(self.tree)
            if spec.groot is not None:
                self._surfaces.add(serve_groot(self.tree, self.catalog, spec.groot, self.notify))
        if self.engine.safety is not None:
            self.engine.safety.contingencies.handlers.update(contingency_handlers(self))
        if spec.web is not None:
            self._surfaces.add(serve_console({spec.robot: self.engine}, self.world,
                                             {spec.robot: None if self.tree is not None else spec.mission},
                                             port=spec.web, host=spec.web_host, notify=self.notify))

    def _check_camera(self) -> None:
        """A vehicle without a camera and a mission that takes photos: a warning before flight (the photos are
        skipped, each behavior says so in the event log)."""
        if not is_tree_document(self.mission) or not callable(getattr(self.robot, "photo_source", None)):
            return
        warning = no_camera(self.mission, str(self.spec.mission))
        if not warning or self.robot.photo_source() != CAMERA_NONE:
            return
        if self.vehicle is not None and not self.vehicle.camera:
            return  # the profile said so: the mission's check has warned already
        wait = getattr(self.robot, "wait_camera", None)
        if callable(wait) and wait(CAMERA_WAIT):  # a camera's heartbeat comes once a second
            return
        self.report(warning[0])

    def _engine(self, choice: RobotChoice, simulated: bool, start: float = 0.0) -> Engine:
        spec = self.spec
        if self.clock is None:
            self.clock = SimulatedClock(start, speed=spec.speed) if simulated else WallClock(start)
        if self.operator is None:
            self.operator = flight_operator(spec)
        return make_engine(spec, choice, self.robot, catalog=self.catalog, clock=self.clock, world=self.world,
                           operator=self.operator, folder=self.folder, vehicle=self.vehicle)

    def _open_journal(self, meta: dict[str, Any], files: list[FlightFile]) -> None:
        """The flight journal: a new one (``files``: those that shaped the flight, with their digests), or the
        interrupted run's going on (a resume)."""
        try:
            self.journal = open_journal(self.engine, self.spec, self.folder, meta,
                                        python=not is_tree_document(self.mission), resumption=self.resumption,
                                        files=files)
        except JournalError as error:
            if error.no_space:
                raise no_space(self.folder, "the journal cannot be written") from None
            raise FlightError(str(error)) from None
        if self.resumption is not None:
            self.notify(f"resuming {self.spec.name} from {self.resumption.point.where()}")

    def _join_fleet(self) -> None:
        from aeroexec.fleet.joined import join_fleet
        from aeroexec.fleet.link import FleetLink
        from aeroexec.fleet.transport import TransportError

        join = self.spec.fleet
        try:
            if self.fleet_node is not None:  # a drone of a fleet flown in this process: the process's node
                self.link = FleetLink(self.fleet_node, join.name, self.engine, join.share, join.telemetry_rate).join()
            else:  # a drone in its own process: a client of the fleet's router
                self._joined = join_fleet(self.engine, join.fleet, join.name, self.folder, self.spec.name,
                                          list(join.connect) or None, join.token, join.share, join.credentials,
                                          dict(join.trust))
                self.link = self._joined.link
                self.notify(f"{join.name} joined fleet {join.fleet}")
        except (TransportError, ValueError) as error:
            raise FlightError(str(error)) from None
        self.link.mission = self.spec.name

    def _tell_fleet(self, state: str) -> None:
        """The fleet hears how this drone's mission ended (its telemetry's status), once more before it leaves."""
        if self.link is not None and self.link.state != state:
            self.link.tell(state)

    # -- the flight ---------------------------------------------------------------------------------
    def start_mission(self) -> None:
        """Start the mission (a tree is ticked by the engine, a Python mission runs in its own thread)."""
        engine = self.engine
        self._mission_started_at = engine.now()
        if self.resumption is None:  # --event, --alert: given at launch, as ``aeroexec ctl add`` gives them later
            for belief in self.spec.beliefs:
                said = engine.supervisor.execute("add", belief, origin="launch")
                self.notify(f"at launch: {said.message}")
        if self.tree is not None and self.resumption is not None:
            self.resumption.start(self.journal, self._tree_rejoined)
        elif self.tree is not None:
            self.tree.start()
            if self.journal is not None:
                self.journal.went_live()
        else:
            recorder = engine.bridge.recorder
            engine.start_mission(recorder.wrap(self.mission) if recorder is not None else self.mission,
                                 self.spec.name)
            if self.journal is not None and self.resumption is None:
                self.journal.went_live()

    def _tree_rejoined(self, reason: str | None) -> None:
        """A resumed tree goes on once the drone is back (or fails with the reason it could not be)."""
        if reason is not None:
            self.tree.halt(reason)
        else:
            self.tree.start()

    def replace_mission(self, mission: Callable[[], Any] | TreeDocument, path: Path) -> None:
        """Fly ``mission`` (checked, from ``path``) in place of the one that ran, now (a ``load``: the running one
        was halted); a tree's ``.btlog`` is ``mission-N.btlog``."""
        engine, name = self.engine, Path(path).name
        self.mission = mission
        if is_tree_document(mission):
            from aeroexec.trees.groot.btlog import BtlogWriter
            from aeroexec.trees.runtime.runner import TreeMission

            self.tree = TreeMission(mission, engine, name=name)
            if self.btlog is not None:
                _quietly(self.btlog.close)
            try:
                self.btlog = BtlogWriter(self.tree, self.folder / f"mission-{self.changes.flown}.btlog",
                                         self.catalog)
            except OSError as error:
                self.btlog = None
                self.notify(f"warning: the tree log of {name} cannot be written: {error}")
            self.tree.start()
        else:
            self.tree = None
            engine.start_mission(mission, name)
        if self.link is not None:
            self.link.mission = name

    @property
    def mission_done(self) -> bool:
        if self.changes is not None and self.changes.busy:  # a new mission is loaded once the old one unwound
            return False
        if self.tree is not None:
            return self.tree.done
        return self.engine.bridge.state == DONE

    def halt_mission(self, reason: str) -> None:
        """Stop the mission where it is (its behaviors stop; the drone is then landed by the ending)."""
        if self.tree is not None:
            self.tree.halt(reason)
        self.engine.bridge.close()

    def time_limit(self) -> None:
        """The mission ran out of time: say so, and halt it. A tree that patrols forever (a Repeat of
        num_cycles -1: DO_JUMP -1) is suspended by it (the way such a mission is meant to stop: exit 5, and
        ``--resume`` patrols on); any other mission failed to finish in time."""
        patrol = _patrol(self.tree.document if self.tree is not None else None)
        if patrol is not None:
            self.engine.log.record("mission_suspended", detail=f"the time limit (--max-time {self.spec.max_time:g} "
                                                               f"s) stopped the patrol that repeats forever: "
                                                               f"{patrol}", time_limit=self.spec.max_time)
        else:
            self.engine.log.record("engine_time_limit",
                                   detail=f"{self.spec.max_time:g} s of engine time have passed")
        self.halt_mission("time limit")

    def interrupted(self, how: str = "Ctrl-C") -> None:
        """The operator interrupted the run (Ctrl-C, SIGTERM, SIGHUP): abort the mission; the ending lands."""
        self.notify(f"interrupted by the operator ({how}): aborting and landing "
                    f"({how} again leaves the drone as it is)")
        self.engine.log.record("operator_interrupt", detail=how)
        self.engine.supervisor.execute("abort", f"{how}: aborted by the operator", origin="keyboard")

    def ending(self) -> FlightEnding:
        """The end of this flight, to be stepped once per engine period (a fleet drives several in lockstep)."""
        return FlightEnding(self.engine, link_grace=self.spec.link_grace)

    def fly(self) -> FlightOutcome:
        """Fly the mission to its end (or the time limit, an abort, Ctrl-C, SIGTERM or SIGHUP), then end the
        flight: land, disarm, record how it ended. Call from the thread that may get KeyboardInterrupt."""
        self.open()
        engine = self.engine
        interrupted = False
        try:
            try:
                self.start_mission()
                if not engine.run_until(lambda: self.mission_done, self.spec.max_time):
                    self.time_limit()
            except KeyboardInterrupt as interrupt:
                self.interrupted(getattr(interrupt, "signal_name", "Ctrl-C"))
                interrupted = True
            faults = None
            while faults is None:
                try:
                    faults = end_flight(engine, link_grace=self.spec.link_grace)
                except KeyboardInterrupt as interrupt:  # the first one while the flight ends: it goes on landing
                    if interrupted:
                        raise
                    self.interrupted(getattr(interrupt, "signal_name", "Ctrl-C"))
                    interrupted = True
        except KeyboardInterrupt:
            self.notify("interrupted again: leaving the drone as it is")
            faults = ["the operator interrupted the end of the flight: the drone was left as it was"]
        return self.finish(faults)

    def finish(self, faults: list[str]) -> FlightOutcome:
        """Record how the flight ended (faults fail it) and close the outputs; the outcome."""
        engine = self.engine
        status = flight_status(engine.log, faults, self.tree, self.catalog,
                               self.resumption.reached if self.resumption is not None else ())
        self._tell_fleet("failed" if status.word == FAILED else
                         "completed" if status.exit_status in (0, 3) else "stopped")
        if self.flight_log is not None:
            self.flight_log.last_records()  # run_ended is in the log only with the rest of the log
        unsaved = next((e.data.get("error") or e.detail for e in engine.log.events("photo_not_saved")), None)
        code = FlightOutcome(status, list(faults), self._incomplete(), self.folder, unsaved).exit_status
        record_run_status(engine.log, status, code)
        if self.journal is not None:
            self.journal.ended(status, code)
        try:
            with interrupts_held():  # the outputs close whole; a signal meanwhile has nothing left to stop
                self.close()
        except KeyboardInterrupt:
            logger.info("interrupted while the outputs closed: they were closed first")
        whole = self.flight_log is not None and self.flight_log.incomplete is None  # run_ended is in the log
        self.outcome = FlightOutcome(status, list(faults), self._incomplete(), self.folder, unsaved,
                                     recorded=code if whole else None)
        return self.outcome

    def _incomplete(self) -> str | None:
        """Why the run's record is incomplete so far (the event log's or the journal's write error), or None."""
        incomplete = self.flight_log.incomplete if self.flight_log is not None else None
        if incomplete is None and self.journal is not None and self.journal.incomplete is not None:
            incomplete = f"the journal: {self.journal.incomplete}"
        if incomplete is None and self.recording is not None and self.recording.error is not None:
            incomplete = f"the recording {self.recording.path}: {self.recording.error}"
        return incomplete

    def _open_recording(self) -> None:
        """The MCAP recording and the Foxglove live view, one recorder fed by the event log as it is written
        (``flight/recording/live.py``)."""
        from aeroexec.flight.recording.live import LiveRecording

        sinks: list[Any] = []
        try:
            if self.spec.foxglove is not None:
                from aeroexec.flight.recording.foxglove_view import FoxgloveView

                try:
                    sinks.append(FoxgloveView(self.spec.foxglove, self.spec.web_host))
                except OSError as error:
                    raise FlightError(f"--foxglove {error}", usage=True) from None
                self.notify(f"foxglove: {sinks[-1].url} (Foxglove: Open connection, Foxglove WebSocket)")
            if self.spec.mcap:
                from aeroexec.flight.recording.mcap_file import McapFile

                try:
                    sinks.append(McapFile(self.spec.mcap))
                except OSError as error:
                    raise FlightError(f"the recording {self.spec.mcap} cannot be written: "
                                      f"{error.strerror or error}", usage=True) from None
        except BaseException:
            for sink in sinks:
                _quietly(lambda sink=sink: sink.close(keep=False))
            raise
        self.recording = LiveRecording(sinks, self.spec.mcap)

    def _warn_of_early_link_loss(self, event: Any) -> None:
        """A link lost on the ground before the mission started is a warning, once per drop, not a fault."""
        if event.kind != "drone_link_lost" or event.data.get("in_air"):
            return
        if self._mission_started_at is not None and event.time >= self._mission_started_at:
            return
        self.notify(f"warning: the link to the vehicle dropped at t={event.time:.1f} s, on the ground, before the "
                    f"mission ({event.detail or 'no reason given'})")
        self.engine.log.record("link_warning", detail=f"link lost on the ground before the mission at "
                                                      f"t={event.time:.1f} s: {event.detail}")

    # -- the end ------------------------------------------------------------------------------------
    def close(self) -> None:
        """Stop the engine and the robot, close every surface and output (idempotent, never hangs)."""
        if self._closed:
            return
        self._closed = True
        parts = [self._surfaces]
        if self.control is not None:
            parts.append(self.control)
        for part in parts:
            _quietly(part.close)
        if self.engine is not None:
            _quietly(self.engine.stop)
        if self._joined is not None:
            _quietly(self._joined.close)
        elif self.link is not None:
            _quietly(self.link.leave)
        for part in (self.flight_log, self.recording, self.journal, self.btlog, self.operator):
            if part is not None:
                _quietly(part.close)
        if self.robot is not None:
            _quietly(self.robot.close)


def _patrol(document: Any) -> str | None:
    """The name of a tree's Repeat forever (a patrol: num_cycles -1), None when it has none."""
    if document is None:
        return None
    stack = [document.root]
    while stack:
        node = stack.pop()
        if node.type == "Repeat" and node.ports.get("num_cycles", "").strip() == "-1":
            return node.name
        stack.extend(node.children)
    return None


def _quietly(close: Callable[[], Any]) -> None:
    try:
        close()
    except Exception:  # one part that fails to close never keeps the others open
        logger.exception("closing %s failed", getattr(close, "__qualname__", close))


__all__ = ["FlightSession"]
