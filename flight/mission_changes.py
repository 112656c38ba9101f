"""The changes of a flight's running mission (``engine.supervisor.changes``): a tree's items changed in place after a
check like a new mission's, a Python mission's running behavior skipped, and a new mission of any format loaded into
the flight.

- Trees (behavior trees, plans, Aerostack2 plans, TML): the change is planned on the running tree
  (:mod:`aeroexec.trees.runtime.changes`), checked from where the drone is (:mod:`aeroexec.trees.change_check`) and,
  when nothing is wrong with it, made between two ticks. A fragment of XML (or ``BEHAVIOR PORT=VALUE``) is read as
  the file ``change N`` (N counts this flight's changes), so what is wrong with it says ``change N:LINE``.
- Python missions: ``skip`` stops the behavior the program waits for (its call returns INTERRUPTED, "skipped by the
  operator"); edits and jumps are refused: a program cannot be edited while it runs.
- ``load FILE``: the file is read and checked on the thread that sent the command (never the engine's), like
  ``aeroexec run`` checks a mission, in the flight's world, and a copy is kept in the output folder
  (``loaded/N-NAME``); then, on the engine's thread, its flight order and route are checked from where the drone is
  now, the running mission is halted (``mission_replaced``; its behaviors stop, the drone holds) and the new one
  starts. A Python mission that is replaced unwinds first (its waiting call raises MissionAborted): the new mission
  starts at the first tick after its thread ended. A Python mission's flight order is checked from the ground: loaded
  while the drone flies, only its requests' formats and values are checked before (the engine refuses a request out
  of order when it comes, FAILED_PRECONDITIONS).
- A safety rule's contingency (:func:`contingency_handlers`): ``subtree ID`` runs that tree of the mission in place of
  the running one, ``call FUNCTION`` preempts a Python mission with that function of it.
"""

from __future__ import annotations

import copy
import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from aeroexec.engine.catalog.contingencies import Call, Subtree
from aeroexec.engine.errors import WRONG_SEQUENCE, Problem
from aeroexec.engine.events import Outcome
from aeroexec.engine.missions.bridge import MissionPreempted
from aeroexec.flight.missions import CheckedMission, MissionFileError, check_mission, mission_function

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.engine.supervision.changes import ChangeOutcome, MissionChange

logger = logging.getLogger(__name__)

CHANGED = "changed by the operator"
UNWIND_TIMEOUT = 10.0  # s of engine time a replaced program has to unwind before the load is given up


@dataclass
class PreparedLoad:
    """A mission file read and checked for ``load`` (on the thread that sent the command)."""

    path: Path
    kept: Path | None = None  # its copy in the output folder
    checked: CheckedMission | None = None
    function: Any = None  # a Python mission's mission()
    refusal: str = ""
    problems: tuple[str, ...] = ()
    ground: tuple[str, ...] = ()  # a program's flight-order errors, from the ground


class MissionChanges:
    """The changes of one :class:`~aeroexec.flight.session.FlightSession`'s mission, set as its supervisor's
    ``changes``."""

    def __init__(self, session: Any) -> None:
        self.session = session
        self.count = 0  # changes received (names the fragments: "change N")
        self.loads = 0  # missions loaded (the copies in the output folder)
        self.flown = 1  # missions flown in this flight (names a loaded tree's .btlog: mission-N.btlog)
        self.replacing: PreparedLoad | None = None  # the load that follows a replaced program once it unwound
        self._unwinding_since = 0.0
        self._changes: dict[int, Any] = {}  # TreeChanges of each tree mission

    @property
    def engine(self) -> Any:
        return self.session.engine

    # -- on the engine's thread ------------------------------------------------------------------------------
    def change(self, change: MissionChange, origin: str, prepared: Any = None) -> ChangeOutcome:
        """Check and make ``change`` now (the supervisor calls it on the engine's thread)."""
        # here, as in each method that makes a change: a flight whose mission is never changed never imports them
        from aeroexec.engine.supervision.changes import ChangeOutcome, program_change

        self.count += 1
        if change.command == "load":
            return self._load(change, prepared if prepared is not None else self.prepare(change))
        if self.replacing is not None:
            return ChangeOutcome(False, "a new mission is being loaded: change it once it flies")
        tree = self.session.tree
        if tree is not None and not tree.done:
            return self._tree_change(tree, change)
        if self.session.mission_done:
            return ChangeOutcome(False, "no mission is running")
        return program_change(self.engine, change)

    def items(self) -> list[dict[str, Any]]:
        tree = self.session.tree
        return self._tree_changes(tree).items() if tree is not None else []

    def _tree_changes(self, tree: Any) -> Any:
        from aeroexec.trees.runtime.changes import TreeChanges

        if id(tree) not in self._changes:
            self._changes = {id(tree): TreeChanges(tree)}
        return self._changes[id(tree)]

    def _tree_change(self, tree: Any, change: MissionChange) -> ChangeOutcome:
        from aeroexec.engine.supervision.changes import ChangeError, ChangeOutcome
        from aeroexec.trees import TreeFormatError  # here: the tree model is a tree mission's only
        from aeroexec.trees.change_check import check_change
        from aeroexec.trees.loaders.fragment import read_fragment

        fragment = []
        if change.fragment or change.command in ("insert", "replace"):  # an empty one is refused, not inserted
            try:
                fragment = read_fragment(change.fragment, f"change {self.count}")
            except TreeFormatError as error:
                said = [f"{file}:{line}: {message}" if line else f"{file}: {message}"
                        for file, line, message in error.problems]
                return ChangeOutcome(False, f"the fragment cannot be read: {said[0]}", said)
        changes = self._tree_changes(tree)
        try:
            plan = changes.plan(change, fragment)
        except ChangeError as error:
            return ChangeOutcome(False, str(error))
        problems = check_change(tree, plan, self.session.world)
        if problems:
            return ChangeOutcome(False, _first(problems), [str(p) for p in problems])
        edits = plan.edits(tree.document)
        ended = changes.apply(plan)
        if ended:
            self.engine.supervisor.drop_suspended(ended, Outcome.INTERRUPTED, CHANGED)
        return ChangeOutcome(True, plan.what, recorded={"edits": edits} if edits else {})

    # -- load ------------------------------------------------------------------------------------------------
    def prepare(self, change: MissionChange) -> PreparedLoad:
        """Read and check the file of a ``load`` (on the thread that sent it: reading a file never holds the loop)."""
        session = self.session
        path = Path(change.mission).expanduser()
        prepared = PreparedLoad(path)
        try:
            checked = check_mission(path, session.catalog, session.world)
        except MissionFileError as error:
            prepared.refusal = str(error)
            return prepared
        # the flight order and the route are checked from where the drone is, once it is known (on the engine's
        # thread); a Python program's order from the ground only
        route = {id(p) for p in (checked.route.problems if checked.route is not None else [])}
        order = [p for p in checked.errors if getattr(p, "kind", "") == WRONG_SEQUENCE]
        errors = [p for p in checked.errors if id(p) not in route and p not in order]
        prepared.checked = checked
        prepared.problems = tuple(str(p) for p in errors)
        prepared.ground = tuple(str(p) for p in order) if checked.tree is None else ()
        if errors:
            prepared.refusal = _first(errors)
            return prepared
        if checked.tree is None:
            try:
                prepared.function = mission_function(path)
            except MissionFileError as error:
                prepared.refusal = str(error)
                return prepared
        prepared.kept = self._keep(path)
        return prepared

    def _keep(self, path: Path) -> Path | None:
        """A copy of a loaded mission in the output folder (``loaded/N-NAME``), for the record."""
        folder = self.session.folder
        if folder is None:
            return None
        self.loads += 1
        kept = folder / "loaded" / f"{self.loads}-{path.name}"
        try:
            kept.parent.mkdir(exist_ok=True)
            import shutil  # here: only a mission loaded in flight is copied

            shutil.copyfile(path, kept)
        except OSError as error:
            logger.warning("the loaded mission %s cannot be copied into the output folder: %s", path, error)
            return None
        return kept

    def _load(self, change: MissionChange, prepared: PreparedLoad) -> ChangeOutcome:
        from aeroexec.engine.supervision.changes import ChangeOutcome, not_cut_short

        if prepared.refusal:
            return ChangeOutcome(False, prepared.refusal, list(prepared.problems))
        engine, session = self.engine, self.session
        if self.replacing is not None:
            return ChangeOutcome(False, "a new mission is already being loaded")
        if session.mission_done:
            return ChangeOutcome(False, "the mission has ended: the flight is ending (start a new run)")
        running = [a.name for a in engine.coordinator.active().values() if a.source == "mission"]
        why = next((not_cut_short(engine.catalog, name) for name in running if not_cut_short(engine.catalog, name)),
                   None)
        if why:
            return ChangeOutcome(False, why)
        checked = prepared.checked
        flying = _flying(engine)
        if checked.tree is not None:
            from aeroexec.trees.change_check import check_new_mission

            problems = check_new_mission(checked.tree, engine, session.world)
            if problems:
                return ChangeOutcome(False, _first(problems), [str(p) for p in problems])
        elif prepared.ground and not flying:  # a program's order from the ground says nothing of a flying drone
            return ChangeOutcome(False, prepared.ground[0], list(prepared.ground))
        reason = f"{prepared.path.name} was loaded in its place"
        if session.tree is not None:
            session.tree.halt(reason, kind="mission_replaced")
            self._start(prepared)
        else:
            engine.log.record("mission_replaced", detail=f"{session.spec.name}: {reason}")
            engine.bridge.close()  # the program's waiting call raises MissionAborted; it unwinds, then the new one
            self._unwinding_since = engine.now()
            for activation in sorted(engine.coordinator.active().values(), key=lambda a: -a.order):
                if activation.source == "mission":  # what the program started ends with it, as a tree's does
                    engine.coordinator.stop(activation.name, reason)
            self.replacing = prepared
            engine.tick_callbacks.append(self._after_unwinding)
        note = " (a Python mission's flight order is checked from the ground only)" if checked.tree is None and \
            flying else ""
        return ChangeOutcome(True, f"{prepared.path.name} loaded in place of the running mission{note}",
                             recorded={"mission": str(prepared.kept or prepared.path.resolve())})

    def _after_unwinding(self) -> None:
        """Start the loaded mission once the replaced program's thread has ended (a tick callback)."""
        from aeroexec.engine.missions.bridge import DONE

        engine = self.engine
        if engine.bridge.state != DONE:
            if engine.now() - self._unwinding_since > UNWIND_TIMEOUT:  # it catches MissionAborted: give the load up
                engine.tick_callbacks.remove(self._after_unwinding)
                self.replacing = None
                engine.log.record("mission_failed", detail=f"the replaced program did not stop within "
                                                           f"{UNWIND_TIMEOUT:g} s: the loaded mission does not fly")
            return
        engine.tick_callbacks.remove(self._after_unwinding)
        prepared, self.replacing = self.replacing, None
        self._start(prepared)

    def _start(self, prepared: PreparedLoad) -> None:
        self.flown += 1
        self.session.replace_mission(prepared.checked.tree if prepared.checked.tree is not None else
                                     prepared.function, prepared.path)

    @property
    def busy(self) -> bool:
        """True while a replaced program unwinds (the flight's mission is not done meanwhile)."""
        return self.replacing is not None


def contingency_handlers(session: Any) -> dict[str, Callable[[str, Any], bool]]:
    """The changes a safety rule's contingency makes to ``session``'s running mission: ``subtree ID`` runs that tree
    of the mission instead; ``call FUNCTION`` that function (the handlers of ``engine.safety.contingencies``)."""
    def subtree(tree_id: str, rule: Any) -> bool:
        if session.tree is None or tree_id not in session.mission.trees:
            return False
        from aeroexec.trees.runtime.runner import TreeMission

        session.tree.halt(f"safety rule {rule.name}: subtree {tree_id}")
        document = copy.copy(session.mission)
        document.main = tree_id
        session.tree = TreeMission(document, session.engine, name=f"{session.spec.name} ({tree_id})")
        session.tree.start()
        return True

    def call(name: str, rule: Any) -> bool:
        function = getattr(session.mission, "__globals__", {}).get(name)
        if session.tree is not None or not callable(function):
            return False
        session.engine.bridge.preempt(MissionPreempted(function, f"safety rule {rule.name}: call {name}"))
        return True

    return {Subtree.name: subtree, Call.name: call}


def _flying(engine: Any) -> bool:
    from aeroexec.drones import LandedState

    return engine.drone.telemetry().landed_state not in (LandedState.ON_GROUND, LandedState.UNKNOWN)


def _first(problems: list[Problem]) -> str:
    first = problems[0]
    where = f"{first.file}:{first.line}: " if first.line else (f"{first.file}: " if first.file else "")
    more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
    return f"{where}{first.message}{more}"


__all__ = ["MissionChanges", "PreparedLoad", "contingency_handlers"]
