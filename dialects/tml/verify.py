"""Verification of a TML mission before flight: the tree checks on the compiled mission, and TML's own on the source.

``verify_tml(document, catalog)`` runs :func:`~.verify.verify_document` on the compiled trees (behavior names,
argument names and values through the specialist, belief expressions, WRONG_SEQUENCE along the main tree's task
order), then adds what only TML has: recurrent behaviors in ``<recurrent_behavior>`` and goal-based ones in
``<behavior>``, the events' condition syntax, every ``+VAR`` bound by an earlier ``<consult>`` on every path that
reaches it, and WRONG_SEQUENCE through the trees events call, from the states the mission can be in when an event
fires. Structural rules were checked when the file was read (:mod:`.tml`).

Paths through events: an event fires while a leaf task of the main tree runs a behavior (see
:mod:`.tml_runtime`), so a tree it calls may use the variables bound before every such task, plus those its
condition binds; its first behaviors are checked from the join of the states before those tasks (with what the
interrupted behavior changes unknown).
"""

from __future__ import annotations

from collections.abc import Iterable

from aeroexec.dialects.tml.compiler import TmlDocument, behavior_name, bindings, uses
from aeroexec.dialects.tml.reader import TmlBehavior, TmlBeliefOperation, TmlEvent, TmlTask
from aeroexec.engine.catalog import BehaviorCatalog, default_catalog
from aeroexec.engine.catalog.descriptors import RECURRENT
from aeroexec.engine.catalog.world_check import WorldMap
from aeroexec.engine.errors import WRONG_FORMAT
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.sequence_check import SequenceChecker, State, join
from aeroexec.trees.verify import Problem, TreeVerifier, verify_document


class _StateRecorder(SequenceChecker):
    """A silent sequence walk of the main tree remembering the states each behavior leaf can start in."""

    def __init__(self, document: TreeDocument, verifier: TreeVerifier) -> None:
        super().__init__(document, verifier.specialist, lambda *args, **kwargs: None)
        self.before: dict[int, State | None] = {}

    def behavior(self, node: TreeNode, behavior: str, state: State):  # type: ignore[override]
        self.before[id(node)] = join(self.before.get(id(node)), state)
        return super().behavior(node, behavior, state)


class TmlVerifier:
    """Collects the TML-specific problems of one compiled mission."""

    def __init__(self, document: TmlDocument, catalog: BehaviorCatalog, world: WorldMap | None = None) -> None:
        self.document, self.catalog = document, catalog
        self.program = document.program
        self.file = document.file
        self.tree = TreeVerifier(document, catalog, known_keys=self.variables(), world=world)
        self.problems: list[Problem] = []

    def variables(self) -> set[str]:
        """Every variable the mission mentions (the tree verifier leaves them to the TML check)."""
        names: set[str] = set()
        for task in self.program.trees.values():
            for sub in task.walk():
                for text in _texts(sub):
                    names |= set(uses(text)) | set(bindings(text))
        for event in self.program.events:
            names |= set(uses(event.condition)) | set(bindings(event.condition))
        return names

    def add(self, line: int, message: str, kind: str = WRONG_FORMAT, severity: str = "error") -> None:
        self.problems.append(Problem(severity, message, self.file, line, kind))

    def verify(self) -> list[Problem]:
        problems = self.tree.verify()
        self.check_recurrent()
        self.check_conditions()
        self.check_variables()
        self.check_called_sequences()
        self.check_unused()
        seen: set[tuple[str, int, str]] = set()
        merged: list[Problem] = []
        for problem in [*problems, *self.tree.problems, *self.problems]:
            key = (problem.file, problem.line, problem.message)
            if key not in seen:
                seen.add(key)
                merged.append(problem)
        merged.sort(key=lambda p: (p.file, p.line))
        return merged

    # -- behaviors -------------------------------------------------------------------------------
    def check_recurrent(self) -> None:
        for root in self.program.trees.values():
            self._recurrent(root, {})

    def _recurrent(self, task: TmlTask, active: dict[str, TmlTask]) -> None:
        for behavior in task.recurrent:
            name = behavior_name(behavior.name)
            descriptor = self.catalog.behavior(name)
            if name in active:
                self.add(behavior.line, f"{name} is already on from the task {active[name].name!r} (line "
                                        f"{active[name].line}): it stays on, it is not activated again",
                         severity="warning")
            if descriptor is not None and descriptor.category != RECURRENT:
                self.add(behavior.line, f"{name} is not a recurrent behavior (it is {descriptor.category}): a "
                                        f"<recurrent_behavior> stays on while its task runs; do it in a leaf task "
                                        f"with <behavior name=\"{behavior.name}\">")
        work = task.work
        if isinstance(work, TmlBehavior):
            descriptor = self.catalog.behavior(behavior_name(work.name))
            if descriptor is not None and descriptor.category == RECURRENT:
                self.add(work.line, f"{descriptor.name} is a recurrent behavior: as the task {task.name!r} it never "
                                    f"completes, so the mission only goes on if an event moves it on (declare it "
                                    f"with <recurrent_behavior> on the task it should accompany)", severity="warning")
        inner = {**active, **{behavior_name(b.name): task for b in task.recurrent}}
        for sub in task.subtasks:
            self._recurrent(sub, inner)

    def check_conditions(self) -> None:
        for event in self.document.events:
            node = TreeNode("Condition", event.name, {"belief": event.condition}, [], self.file, event.condition_line)
            self.tree.check_expression(node, "condition", event.condition)

    # -- variables -------------------------------------------------------------------------------
    def check_variables(self) -> None:
        fire_points: list[tuple[TmlTask, set[str]]] = []
        main = self.program.trees.get(self.program.root_task)
        if main is not None:
            self._flow(main, set(), None, fire_points)
        for event in self.program.events:
            if not fire_points:
                self.add(event.line, f"the event {event.name!r} can never fire: events are checked while the main "
                                     f"tree waits for a behavior, and it runs none", severity="warning")
                continue
            known = set.intersection(*(bound for _, bound in fire_points))
            for variable in uses(event.condition):
                if variable not in known:
                    self._unbound(event.condition_line, variable, event, fire_points)
            if event.call and event.call in self.program.trees:
                self._flow(self.program.trees[event.call], known | set(bindings(event.condition)),
                           (event, fire_points), None)

    def _flow(self, task: TmlTask, bound: set[str], event: tuple[TmlEvent, list] | None,
              fire_points: list[tuple[TmlTask, set[str]]] | None) -> set[str]:
        """Walk a task in order with the variables bound; report uses of unbound ones; the set after it."""
        for behavior in task.recurrent:
            self._uses(behavior, bound, event)
        work = task.work
        if isinstance(work, TmlBehavior):
            if fire_points is not None:
                fire_points.append((task, set(bound)))
            self._uses(work, bound, event)
        elif isinstance(work, TmlBeliefOperation):
            for variable in uses(work.belief):
                if variable not in bound:
                    self._not_bound(work.line, variable, event)
            if work.kind == "consult":
                bound = bound | set(bindings(work.belief))
        for sub in task.subtasks:
            bound = self._flow(sub, bound, event, fire_points)
        return bound

    def _uses(self, behavior: TmlBehavior, bound: set[str], event: tuple[TmlEvent, list] | None) -> None:
        for argument in behavior.arguments:
            for variable in uses(argument.value):
                if variable not in bound:
                    self._not_bound(argument.line, variable, event)

    def _not_bound(self, line: int, variable: str, event: tuple[TmlEvent, list] | None) -> None:
        if event is None:
            self.add(line, f"+{variable} is not bound: no earlier <consult> binds ?{variable} on the way to it")
        else:
            self._unbound(line, variable, *event)

    def _unbound(self, line: int, variable: str, event: TmlEvent, fire_points: list[tuple[TmlTask, set[str]]]
                 ) -> None:
        """A variable an event's condition or tree uses: a warning when some of the places the event can fire
        have it bound (the run fails clearly if it fires at another), an error when none has."""
        task = next(t for t, bound in fire_points if variable not in bound)
        if any(variable in bound for _, bound in fire_points):
            self.add(line, f"+{variable} may not be bound when the event {event.name!r} fires: it can fire during "
                           f"the task {task.name!r} (line {task.line}), before any <consult> binds ?{variable} "
                           f"(if it does, the mission fails there)", severity="warning")
        else:
            self.add(line, f"+{variable} is not bound when the event {event.name!r} fires: no <consult> binds "
                           f"?{variable} before any task it can fire during")

    # -- sequences through events ------------------------------------------------------------------
    def check_called_sequences(self) -> None:
        document = self.document
        if document.main not in document.trees or not document.task_leaves:
            return
        recorder = _StateRecorder(document, self.tree)
        recorder.check()
        states = [recorder.forget(recorder.before.get(id(leaf)), recorder.touched(leaf))
                  for leaf in document.task_leaves]
        entry = join(*states)
        if entry is None:
            return
        for name in dict.fromkeys(e.call for e in document.events if e.call and e.call in document.trees):
            checker = SequenceChecker(document, self.tree.specialist, self.tree.report)
            checker.stack = [name]
            checker.flow(document.trees[name], dict(entry), False)

    def check_unused(self) -> None:
        called = {e.call for e in self.program.events}
        for name, task in self.program.trees.items():
            if name != self.program.root_task and name not in called:
                self.add(task.line, f"the task tree {name!r} never runs: it is not the mission's root task and no "
                                    f"event calls it", severity="warning")


def _texts(task: TmlTask) -> Iterable[str]:
    for behavior in task.recurrent:
        yield from (a.value for a in behavior.arguments)
    if isinstance(task.work, TmlBehavior):
        yield from (a.value for a in task.work.arguments)
    elif isinstance(task.work, TmlBeliefOperation):
        yield task.work.belief


def verify_tml(document: TmlDocument, catalog: BehaviorCatalog | None = None,
               world: WorldMap | None = None) -> list[Problem]:
    """Every problem of a compiled TML mission, sorted by line (literal destinations against ``world``)."""
    return TmlVerifier(document, catalog if catalog is not None else default_catalog(), world).verify()


def verify_tml_document(document: TreeDocument, catalog: BehaviorCatalog | None = None,
                        world: WorldMap | None = None) -> list[Problem] | None:
    """Every problem of a TML mission; None for any other document. The flight asks it before the tree checks (the
    entry-point group ``aeroexec.tree_verifiers``)."""
    return verify_tml(document, catalog, world) if isinstance(document, TmlDocument) else None


def verify_mission_document(document: TreeDocument, catalog: BehaviorCatalog | None = None,
                            world: WorldMap | None = None) -> list[Problem]:
    """Every problem of a mission read by ``load_mission_tree``: a TML mission or a behavior tree (checked
    against ``world`` too when given)."""
    if isinstance(document, TmlDocument):
        return verify_tml(document, catalog, world)
    return verify_document(document, catalog, world=world)
