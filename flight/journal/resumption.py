"""A flight set up to go on from a :class:`~aeroexec.flight.journal.resume_point.ResumePoint`: the simulated drone
made again where the journal last saw it, the beliefs and the tree (or the Python mission's calls) restored, then,
once the mission is about to go on, the drone put back where the mission left it (:class:`~.rejoin.Rejoin`), the
behaviors it had running in the background started again, and the mission live.

A tree goes live when the rejoin is done; a Python mission replays its calls first (at once, nothing acts), and the
rejoin runs at its first call the journal has no result for, so a mission that diverges is refused before the
drone moves.
"""

from __future__ import annotations

import ast
import json
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

from aeroexec.beliefs import parse_belief
from aeroexec.engine.api import list_to_tuple
from aeroexec.engine.errors import RequestRejected
from aeroexec.engine.events import Outcome, achieved_goal_message
from aeroexec.engine.missions.replay import MissionRecorder, location
from aeroexec.engine.missions.values import canonical, decode
from aeroexec.flight.journal.identity import check_belongs, check_files, flight_files, last_logged_time
from aeroexec.flight.journal.opening import open_journal  # here too: its old place
from aeroexec.flight.journal.rejoin import FLYING, Rejoin
from aeroexec.flight.journal.resume_point import ResumePoint, behavior_of
from aeroexec.flight.journal.schema import journal_path
from aeroexec.flight.spec import FlightError, FlightSpec

logger = logging.getLogger(__name__)

FULL = 100.0  # % of a swapped battery
PERIOD = 0.05  # s: the engine's period, the most a resumed run's clock may lose


class RejoinFailed(RequestRejected):
    """The drone could not be put back where the interrupted mission left it: the mission does not go on (raised
    at the mission's first live call, ``where``)."""

    def __init__(self, message: str, where: str) -> None:
        super().__init__("REJOIN", f"{where}: {message}" if where else message, where=where)

    def __str__(self) -> str:
        return self.message


class Resumption:
    """Applies ``point`` to one flight (the session calls these in order: :meth:`place`, :meth:`restore_beliefs`,
    :meth:`restore_tree` or :meth:`recorder`, then :meth:`start` when the mission is to start)."""

    def __init__(self, point: ResumePoint) -> None:
        self.point = point
        self.engine: Any = None
        self.journal: Any = None
        self.tree: Any = None
        self.under_way: dict[str, dict[str, Any]] = {}
        self.settled: dict[str, tuple[str, Any]] = dict(point.settled)
        self._answer: Any = None  # what the Python mission's call under way is answered with, when settled
        self.reached: set[int] = set()  # the tree's nodes (places from 1) that had succeeded before the resume

    def check(self, spec: FlightSpec, world: str | None, log: Path) -> None:
        """JournalError, before anything is written or flown, when this flight is not the interrupted run's to go
        on with: its journal copied from another run's folder, a file that shaped it changed since (the mission,
        the world, the catalog, the rules), times the clock cannot go on from; the resumed run's clock goes on from
        the event log's last record when that is later than the journal's (a ``kill -9`` between two commits)."""
        point = self.point
        journal = journal_path(point.folder)
        check_belongs(journal, point.meta, point.folder, log)
        check_files(journal, point.meta.get("files"),
                    flight_files(spec.mission, world, spec.catalog, spec.rules, spec.safety_rules,
                                 spec.vehicle))
        logged = last_logged_time(log)
        if logged is not None:
            point.time = max(point.time, round(logged + PERIOD, 3))

    @property
    def run(self) -> str:
        """The interrupted run's identity (the resumed run keeps it)."""
        return str(self.point.meta["run"])

    @property
    def supersede_from(self) -> int | None:
        """A Python mission's first call made live again (the journal's later calls are superseded then)."""
        if self.point.kind == "tree":
            return None
        settled = self.point.settled_call
        return settled.number if settled is not None else len(self.point.calls) + 1

    def place(self, robot: Any) -> None:
        """A simulated drone is made again where the journal last saw it: hovering there when the process was
        killed in flight, on the ground otherwise; with a full battery after a suspension (the swap)."""
        place = getattr(robot, "place", None)
        drone = self.point.drone
        if place is None or drone is None:
            return
        crashed = self.point.stop is None
        battery = FULL if self.point.suspended else drone.get("battery")
        place(tuple(drone["position"]), float(drone.get("yaw") or 0.0),
              flying=crashed and drone.get("landed_state") in FLYING, battery_percent=battery)

    def restore_beliefs(self, engine: Any) -> None:
        """The beliefs held when the mission stopped, each persistent one with what was left of its lifetime; a
        predicate the mission declared by adding it (``add_belief``) is declared again as it was."""
        self.engine = engine
        now = engine.now()
        memory = engine.memory
        multivalued = self._declared()
        for text, expires_at in self.point.beliefs:
            remaining = None if expires_at is None else expires_at - now
            if remaining is not None and remaining <= 0:
                continue
            try:
                belief = parse_belief(text)
                if not memory.accepts(belief.name):
                    memory.declare(belief.name, len(belief.args), multivalued=multivalued.get(belief.name, False))
                memory.restore(belief, remaining)
            except Exception as error:  # a belief this flight cannot hold: said, the rest goes on
                logger.warning("the belief %s is not restored: %s", text, error)

    def _declared(self) -> dict[str, bool]:
        """The predicates the Python mission declared by adding beliefs of them: name -> multivalued."""
        found: dict[str, bool] = {}
        for call in self.point.calls:
            if call.function == "add_belief":
                args, kwargs = decode(json.loads(call.arguments))
                text = str(args[0] if args else kwargs.get("belief", ""))
                found[text.split("(", 1)[0].strip()] = bool(kwargs.get("multivalued", args[1] if len(args) > 1
                                                                        else False))
        return found

    def check_program(self, path: Path) -> None:
        """FlightError for a Python mission whose calls cannot be replayed: one that flies through an API a dialect
        names unjournaled (:attr:`StandIns.unjournaled`: Aerostack2's Python API, whose behavior runs are not journaled
        calls of the mission API)."""
        from aeroexec.engine.missions.source import parse_source
        from aeroexec.engine.missions.standins import unjournaled

        from aeroexec.limits import read_text

        for node in ast.walk(parse_source(read_text(path, what="the mission"), str(path))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module] if isinstance(node, ast.ImportFrom) and node.module else [])
            api = next((title for title in map(unjournaled, names) if title), None)
            if api is not None:
                raise FlightError(f"{path}:{node.lineno}: a mission flown through {api} cannot be resumed: its calls "
                                  f"are not journaled; fly it again from its start (aeroexec run {path.name})")

    def change_document(self, document: Any, mission: Any = "the mission") -> None:
        """Make on the tree's document, read again from its file, the changes made to it in flight (before its
        state was kept), so the tree built from it is the one that flew (FlightError when they do not fit)."""
        if not self.point.edits:
            return
        from aeroexec.trees import TreeFormatError
        from aeroexec.trees.loaders.fragment import read_fragment
        from aeroexec.trees.runtime.changes import replay_edits

        try:
            replay_edits(document, self.point.edits, read_fragment)
        except (KeyError, ValueError, TreeFormatError) as error:
            raise FlightError(f"{mission}: the changes made to it in flight do not fit it now ({error}); resume with "
                              f"the mission as it was") from None

    def check_tree(self, document: Any, engine: Any, mission: Any = "the mission") -> None:
        """Make the changes made in flight on ``document`` (:meth:`change_document`) and check the tree built from
        it takes the kept state, on a tree of its own: FlightError before anything is written when it does not."""
        from aeroexec.trees.runtime.runner import TreeMission
        from aeroexec.trees.runtime.tree_state import TreeState, TreeStateError, restore_mission

        self.change_document(document, mission)
        try:
            restore_mission(TreeMission(document, engine),
                            TreeState.from_json(self.point.tree or "", self.point.meta.get("tree_shape")))
        except (TreeStateError, ValueError) as error:
            raise FlightError(f"{mission}: it is not the tree the interrupted run flew ({error}); run it from the "
                              f"start, or resume with the mission as it was") from None

    def restore_tree(self, tree: Any, mission: Any = "the mission") -> None:
        """Put the tree's kept state back (FlightError when ``mission``'s tree is not the one interrupted); the
        leaves whose goal was reached meanwhile are settled."""
        from aeroexec.trees.runtime.nodes.behavior_leaves import BehaviorLeaf
        from aeroexec.trees.runtime.tree_state import TreeState, TreeStateError, restore_mission, walk

        self.tree = tree
        try:
            restore_mission(tree, TreeState.from_json(self.point.tree or "", self.point.meta.get("tree_shape")))
            self.reached = {uid for uid, (_, node) in enumerate(tree.nodes, 1) if node.status.name == "SUCCESS"}
        except (TreeStateError, ValueError) as error:
            raise FlightError(f"{mission}: it is not the tree the interrupted run flew ({error}); run it from the "
                              f"start, or resume with the mission as it was") from None
        for _, node in walk(tree.root):  # what a node put in the engine before (AddRule's rules): put back
            resumed = getattr(node, "resumed", None)
            if callable(resumed):
                resumed(tree.engine)
        running = [node for _, node in walk(tree.root)
                   if isinstance(node, BehaviorLeaf) and node.status.name == "RUNNING"]
        self._leaves = {leaf.behavior: leaf for leaf in running}
        self.under_way = {name: self._arguments(name) for name in self._leaves if name not in self.settled}
        for name, (why, result) in self.settled.items():
            leaf = self._leaves.get(name)
            if leaf is not None:
                leaf.ended = (Outcome.GOAL_ACHIEVED, f"{achieved_goal_message(name)} ({why})", result)

    def recorder(self, engine: Any, journal: Any) -> MissionRecorder:
        """The Python mission's recorder: its kept calls replayed, then live (after the rejoin)."""
        self.engine, self.journal = engine, journal
        pending = self.point.pending
        owned = behavior_of(pending) if pending is not None else None
        self.under_way = {owned: self._arguments(owned)} if owned else {}
        return MissionRecorder(journal, engine.now, replay=self.point.calls, pending=pending, on_live=self._live)

    def _arguments(self, behavior: str) -> dict[str, Any]:
        return next((dict(r["arguments"]) for r in self.point.active if r["behavior"] == behavior), {})

    # -- going on -------------------------------------------------------------------------------------------
    def start(self, journal: Any, then: Callable[[str | None], None]) -> None:
        """On the engine's thread: rejoin, start the background behaviors again, go live; ``then(reason)`` after
        (``reason`` None when the mission may go on)."""
        self.journal = journal
        engine = self.engine
        rejoin = Rejoin(engine, self.point.place, self.point.was_flying, dict(self.under_way))
        engine.log.record("mission_resumed", detail=f"from {self.point.where()}", segment=journal.segment)

        def rejoined(reason: str | None) -> None:
            if reason is not None:
                engine.log.record("rejoin_failed", detail=reason)
                then(f"the drone could not rejoin the mission: {reason}")
                return
            self._background()
            journal.went_live()
            settled = self.point.settled_call
            if settled is not None:  # its result is kept again, in this part of the run
                journal.call_returned(settled.number, settled.function, settled.arguments, settled.location,
                                      engine.now(), canonical(settled.result), None)
            for name, why in rejoin.settled:
                self._settle(name, why)
            then(None)

        rejoin.start(rejoined)

    def _background(self) -> None:
        """The behaviors the mission had running besides the one under way, started again as they were."""
        engine = self.engine
        started = getattr(getattr(self.tree, "context", None), "started", None)
        for row in self.point.active:
            if row["behavior"] in self.under_way or row["behavior"] in self.settled:
                continue
            arguments = {k: list_to_tuple(v) for k, v in row["arguments"].items()}
            result = engine.coordinator.activate(row["behavior"], arguments, priority=row["priority"],
                                                 source=row["source"])
            if result.accepted and started is not None:
                started.append(result.activation)

    def _settle(self, name: str, why: str) -> None:
        """A goal under way reached without its behavior (the drone landed, or flies at its take-off height)."""
        message = f"{achieved_goal_message(name)} ({why}, on resuming)"
        self.engine.log.record(Outcome.GOAL_ACHIEVED.value, name, message, source="mission", resumed=True)
        leaf = getattr(self, "_leaves", {}).get(name)
        if leaf is not None:
            leaf.ended = (Outcome.GOAL_ACHIEVED, message, None)
            return
        pending = self.point.pending
        if pending is not None and behavior_of(pending) == name:
            self._answer = {"execute_behavior": Outcome.GOAL_ACHIEVED, "ask_behavior": None,
                            "run_behavior": (True, Outcome.GOAL_ACHIEVED)}.get(pending.function)
            self._answer = (self._answer,)

    def _live(self) -> tuple[Any] | None:
        """The Python mission's first live call: the rejoin first (the mission's thread waits for it); the answer
        of the call under way when its goal is reached by the rejoin."""
        error = self.engine.bridge.wait_for(lambda resolve: self.start(self.journal, resolve))
        if error is not None:
            raise RejoinFailed(error, location())
        return self._answer


__all__ = ["RejoinFailed", "Resumption", "open_journal"]
