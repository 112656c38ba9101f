"""Reading TML missions (Aerostack's task-based mission language, Levant dialect) into a program model with lines.

The file is XML read with the same parser as behavior trees (:func:`~.xml_loader.parse_xml`: expat, refusing
what ``defusedxml`` refuses)::

    <mission root_task="Search for object">
      <task_tree>
        <task name="Search for object">
          <task name="Initial phase">
            <recurrent_behavior name="SELF_LOCALIZE_BY_ODOMETRY"/>
            <task name="Remember home"><consult belief="position(self, (?HOME_X, ?HOME_Y, ?))"/></task>
            <task name="Take off"><behavior name="TAKE_OFF"/></task>
          </task>
          ...
      </task_tree>
      <event_handling>
        <event name="Low battery">
          <condition belief="battery_level(self, low)"/>
          <call root_task="Emergency land"/>
          <termination mode="ABORT_MISSION"/>
        </event>
      </event_handling>
    </mission>

Structural rules are checked here (allowed elements and attributes, a leaf task does exactly one behavior or
belief operation and a complex task none, ``root_task`` and ``call`` name the root task of some task tree,
termination modes); names and values against the catalog, belief syntax, ``+VAR`` bindings and WRONG_SEQUENCE
are checked by :mod:`.tml_verify` on the compiled mission. The older Gregale dialect (``<action>``, ``<skill>``,
tasks straight under ``<mission name>``) is refused with a message naming it. Every problem found is raised
together as one :class:`~.model.TreeFormatError`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.engine.yaml_nodes import suggestion
from aeroexec.trees.loaders.xml_loader import _Element, parse_xml
from aeroexec.trees.model import TreeFormatError

from aeroexec.limits import InputError, read_bytes

logger = logging.getLogger(__name__)

TERMINATION_MODES = ("REPEAT_TASK", "NEXT_TASK", "END_MISSION", "ABORT_MISSION")
BELIEF_OPERATIONS = ("add", "remove", "consult")
#: Element -> (its attributes, the required ones, the elements it may contain).
GRAMMAR: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]] = {
    "mission": (("root_task", "name"), (), ("task_tree", "event_handling")),
    "task_tree": ((), (), ("task",)),
    "task": (("name",), ("name",), ("recurrent_behavior", "behavior", *BELIEF_OPERATIONS, "task")),
    "recurrent_behavior": (("name",), ("name",), ("argument",)),
    "behavior": (("name",), ("name",), ("argument",)),
    "argument": (("name", "value"), ("value",), ()),  # the name is optional (the behavior's one argument)
    "add": (("belief",), ("belief",), ()),
    "remove": (("belief",), ("belief",), ()),
    "consult": (("belief",), ("belief",), ()),
    "event_handling": ((), (), ("event",)),
    "event": (("name",), ("name",), ("condition", "call", "termination")),
    "condition": (("belief",), ("belief",), ()),
    "call": (("root_task",), ("root_task",), ()),
    "termination": (("mode",), ("mode",), ()),
}
#: Elements only the older dialects have (Gregale v1 and the 2016 prototype).
GREGALE_ELEMENTS = ("action", "skill", "repeat", "ending", "macro_task")


@dataclass
class TmlArgument:
    name: str  # as written ("" when left out)
    value: str
    line: int


@dataclass
class TmlBehavior:
    """``<behavior>`` or ``<recurrent_behavior>`` with its arguments."""

    name: str
    arguments: list[TmlArgument]
    line: int
    recurrent: bool = False


@dataclass
class TmlBeliefOperation:
    """``<add>``, ``<remove>`` or ``<consult>``."""

    kind: str
    belief: str
    line: int


@dataclass
class TmlTask:
    """A task: a leaf does ``work`` (one behavior or belief operation); a complex task runs ``subtasks`` in order."""

    name: str
    line: int
    recurrent: list[TmlBehavior] = field(default_factory=list)
    work: TmlBehavior | TmlBeliefOperation | None = None
    subtasks: list[TmlTask] = field(default_factory=list)

    def walk(self):
        yield self
        for task in self.subtasks:
            yield from task.walk()


@dataclass
class TmlEvent:
    """``<event>``: when ``condition`` becomes true, run the tree rooted at ``call`` (if any), then ``mode``."""

    name: str
    line: int
    condition: str
    condition_line: int
    call: str | None
    call_line: int
    mode: str
    mode_line: int


@dataclass
class TmlProgram:
    """A TML mission: its task trees by root task name, the one run at start, and its event handlers."""

    file: str
    root_task: str
    line: int
    trees: dict[str, TmlTask]
    events: list[TmlEvent]


class _Reader:
    def __init__(self, file: str) -> None:
        self.file = file
        self.problems: list[tuple[str, int, str]] = []

    def error(self, line: int, message: str) -> None:
        self.problems.append((self.file, line, message))

    def check(self, element: _Element) -> None:
        """Attributes of ``element`` (known, required, not empty) and the tags of its children."""
        attributes, required, children = GRAMMAR[element.tag]
        for attribute in element.attrs:
            if attribute not in attributes:
                allowed = f"expected {', '.join(attributes)}" if attributes else "it takes none"
                self.error(element.line, f"unknown attribute {attribute} of <{element.tag}> ({allowed})"
                                         f"{suggestion(attribute, attributes) if attributes else ''}")
        for attribute in required:
            if not element.attrs.get(attribute, "").strip():
                self.error(element.line, f"<{element.tag}> needs {attribute}=\"...\"")
        for child in element.children:
            if child.tag in GREGALE_ELEMENTS:
                self.error(child.line, f"<{child.tag}> belongs to TML's older Gregale dialect; aeroexec reads the "
                                       f"Levant dialect (write <behavior> or <recurrent_behavior>)")
            elif child.tag not in children:
                allowed = ", ".join(f"<{c}>" for c in children) if children else "nothing"
                self.error(child.line, f"unknown element <{child.tag}> in <{element.tag}>: expected {allowed}"
                                       f"{suggestion(child.tag, children) if children else ''}")

    def program(self, root: _Element) -> TmlProgram:
        self.check(root)
        trees: dict[str, TmlTask] = {}
        events: list[TmlEvent] = []
        handling = [c for c in root.children if c.tag == "event_handling"]
        for extra in handling[1:]:
            self.error(extra.line, "a mission has at most one <event_handling>")
        for child in root.children:
            if child.tag == "task_tree":
                task = self.task_tree(child)
                if task is None:
                    continue
                if task.name in trees:
                    self.error(task.line, f"two task trees have the root task {task.name!r} "
                                          f"(first at line {trees[task.name].line})")
                    continue
                trees[task.name] = task
            elif child.tag == "event_handling":
                self.check(child)
                events += [e for e in (self.event(c) for c in child.children if c.tag == "event") if e]
        if not trees:
            self.error(root.line, "the mission has no <task_tree>")
        root_task = root.attrs.get("root_task", "").strip()
        if not root_task:
            if "name" in root.attrs and len(trees) == 1:
                root_task = next(iter(trees))  # the wiki's first snippet writes <mission name=...>
            elif trees:
                self.error(root.line, "<mission> needs root_task=\"...\", the root task of the tree run at start")
        elif trees and root_task not in trees:
            self.error(root.line, f"root_task names {root_task!r}, but no task tree has that root task"
                                  f"{suggestion(root_task, trees)} (root tasks: {', '.join(trees)})")
        self.calls(events, trees, root_task)
        return TmlProgram(self.file, root_task, root.line, trees, events)

    def task_tree(self, element: _Element) -> TmlTask | None:
        self.check(element)
        tasks = [c for c in element.children if c.tag == "task"]
        if len(tasks) != 1:
            detail = "it has none" if not tasks else f"it has {len(tasks)} (put them under one task)"
            self.error(element.line, f"a <task_tree> holds exactly one root <task>: {detail}")
        return self.task(tasks[0]) if tasks else None

    def task(self, element: _Element) -> TmlTask:
        self.check(element)
        task = TmlTask(element.attrs.get("name", "").strip() or f"task at line {element.line}", element.line)
        work: list[TmlBehavior | TmlBeliefOperation] = []
        for child in element.children:
            if child.tag == "recurrent_behavior":
                task.recurrent.append(self.behavior(child, recurrent=True))
            elif child.tag == "behavior":
                work.append(self.behavior(child))
            elif child.tag in BELIEF_OPERATIONS:
                self.check(child)
                work.append(TmlBeliefOperation(child.tag, child.attrs.get("belief", "").strip(), child.line))
            elif child.tag == "task":
                task.subtasks.append(self.task(child))
        if task.subtasks and work:
            first = work[0]
            what = f"<behavior name=\"{first.name}\">" if isinstance(first, TmlBehavior) else f"<{first.kind}>"
            self.error(first.line, f"the task {task.name!r} has subtasks, so it is a complex task: it cannot also "
                                   f"have {what} (a complex task has no behavior or belief operation; "
                                   f"put it in a subtask)")
        elif len(work) > 1:
            self.error(work[1].line, f"the leaf task {task.name!r} has {len(work)} behaviors or belief operations: "
                                     f"a leaf task has exactly one (make each a subtask)")
        elif not task.subtasks and not work and all(c.tag in GRAMMAR for c in element.children):
            self.error(element.line, f"the task {task.name!r} does nothing: a leaf task needs one <behavior>, "
                                     f"<add>, <remove> or <consult>, a complex task one or more <task>")
        task.work = work[0] if work and not task.subtasks else None
        return task

    def behavior(self, element: _Element, recurrent: bool = False) -> TmlBehavior:
        self.check(element)
        arguments = []
        for child in element.children:
            if child.tag == "argument":
                self.check(child)
                arguments.append(TmlArgument(child.attrs.get("name", "").strip(), child.attrs.get("value", ""),
                                             child.line))
        return TmlBehavior(element.attrs.get("name", "").strip(), arguments, element.line, recurrent)

    def event(self, element: _Element) -> TmlEvent | None:
        self.check(element)
        name = element.attrs.get("name", "").strip() or f"event at line {element.line}"
        parts: dict[str, list[_Element]] = {}
        for child in element.children:
            if child.tag in ("condition", "call", "termination"):
                self.check(child)
                parts.setdefault(child.tag, []).append(child)
        for tag in ("condition", "call", "termination"):
            found = parts.get(tag, [])
            if len(found) > 1:
                self.error(found[1].line, f"the event {name!r} has {len(found)} <{tag}>: at most one")
            elif not found and tag != "call":
                self.error(element.line, f"the event {name!r} needs a <{tag}>")
        condition = parts.get("condition", [None])[0]
        call = parts.get("call", [None])[0]
        termination = parts.get("termination", [None])[0]
        mode = termination.attrs.get("mode", "").strip() if termination is not None else ""
        if termination is not None and mode and mode not in TERMINATION_MODES:
            self.error(termination.line, f"unknown termination mode {mode!r}: expected one of "
                                         f"{', '.join(TERMINATION_MODES)}{suggestion(mode, TERMINATION_MODES)}")
        if condition is None or termination is None:
            return None
        return TmlEvent(name, element.line, condition.attrs.get("belief", "").strip(), condition.line,
                        call.attrs.get("root_task", "").strip() if call is not None else None,
                        call.line if call is not None else 0, mode, termination.line)

    def calls(self, events: list[TmlEvent], trees: dict[str, TmlTask], root_task: str) -> None:
        for event in events:
            if not event.call:
                continue
            if event.call == root_task:
                self.error(event.call_line, f"the event {event.name!r} calls {event.call!r}, the mission's root "
                                            f"task: an event can only call another task tree")
            elif event.call not in trees:
                self.error(event.call_line, f"the event {event.name!r} calls {event.call!r}, but no task tree "
                                            f"has that root task{suggestion(event.call, trees)} "
                                            f"(root tasks: {', '.join(trees) or 'none'})")


def _gregale_marks(root: _Element) -> list[str]:
    """What in a document only Gregale's TML has: ``<action>``, ``<skill>``, ``<macro_task>``, ``<repeat>``,
    ``<condition parameter=...>``, tasks straight under ``<mission>``."""
    marks: list[str] = []
    if any(c.tag == "task" for c in root.children):
        marks.append("<task> directly under <mission>")
    stack = list(root.children)
    while stack and len(marks) < 3:
        element = stack.pop(0)
        if element.tag in GREGALE_ELEMENTS and f"<{element.tag}>" not in marks:
            marks.append(f"<{element.tag}>")
        elif element.tag == "condition" and "parameter" in element.attrs and "<condition parameter>" not in marks:
            marks.append("<condition parameter>")
        stack.extend(element.children)
    return marks


def gregale_refusal(root: _Element) -> str | None:
    """Why a ``<mission>`` is in the older Gregale dialect (or the 2016 prototype's), None when it is not."""
    marks = _gregale_marks(root)
    if marks:
        return (f"this TML mission is in the older Gregale dialect (TML v1: {', '.join(marks)}); aeroexec reads "
                f"TML's Levant dialect (v2): put the tasks in <task_tree> elements, write <behavior> for actions "
                f"and <recurrent_behavior> for skills, <condition belief=...> for conditions, and name the tree to "
                f"run with <mission root_task=\"...\">")
    return None


def is_tml(root: _Element) -> bool:
    """True when an XML document is a TML mission: its document element is ``<mission>`` with TML's attributes or
    elements (an empty ``<mission/>`` is left to the behavior-tree reader, which says what it expects)."""
    return root.tag == "mission" and (bool(set(root.attrs) & {"root_task", "name"}) or any(
        c.tag in ("task_tree", "task", "event_handling", *GREGALE_ELEMENTS) for c in root.children))


def read_tml_root(root: _Element, file: str) -> TmlProgram:
    """The TML program of a parsed document whose element is ``<mission>``."""
    refusal = gregale_refusal(root)
    if refusal:
        raise TreeFormatError([(file, root.line, refusal)])
    reader = _Reader(file)
    program = reader.program(root)
    if reader.problems:
        raise TreeFormatError(sorted(reader.problems, key=lambda p: p[1]))
    logger.debug("read the TML mission %s: %d task trees, %d events", file, len(program.trees), len(program.events))
    return program


def read_tml(data: bytes | str, file: str = "<tml>") -> TmlProgram:
    """A TML program from XML text (``file`` names it in problems)."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    root = parse_xml(raw, file)
    if not is_tml(root):
        raise TreeFormatError([(file, root.line, f"not a TML mission: the document element is <{root.tag}>, "
                                                 f"not <mission>")])
    return read_tml_root(root, file)


def file_bytes(path: str | Path) -> bytes:
    """The bytes of a mission file; a TreeFormatError when it cannot be read."""
    try:
        return read_bytes(path)
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None


def load_tml(path: str | Path) -> TmlProgram:
    """A TML program from a file."""
    return read_tml(file_bytes(path), str(path))
