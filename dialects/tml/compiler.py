"""Compiling a TML program into the behavior-tree model, so it runs on the tree runtime and is verified like a tree.

Each task tree becomes one tree of the :class:`TmlDocument` (named by its root task), and each task a node named
after it, at its line:

==============================  ===============================================================================
leaf task with ``<behavior>``   the catalog behavior's leaf; arguments become ports (``+X`` -> ``{X}``)
leaf task with a belief op      ``QueryBelief`` (consult: its ``?X`` are written as variable ``X``),
                                ``AddBelief`` (add), ``RemoveBelief`` (remove)
complex task                    ``SequenceWithMemory`` of its subtasks (halting keeps the place, which is how an
                                event handler resumes the mission)
``<recurrent_behavior>``        the task becomes ``Parallel(success_count=1, failure_count=1)`` of the recurrent
                                behaviors' leaves (activated first, in order) and the task's body: they are on
                                while the task runs and stopped when it ends; one already on from an enclosing
                                task is not activated again
==============================  ===============================================================================

An ``<argument value>`` without ``name`` (the Levant wiki says the name is optional) is the behavior's one
argument. All trees share one blackboard: TML's variables are global to the mission. ``TmlDocument.build`` (called by
``build_tree``) wraps the main tree and the trees events call in a :class:`~.tml_runtime.TmlEventHandling` node.
Levant names that the aerial catalog spells differently are translated: ``REQUEST_OPERATOR_ASSISTANCE``
(``message``, ``options``) is ``ASK_OPERATOR`` (``QUESTION``, ``POSSIBLE_ANSWERS``); ``WAIT``'s ``timeout`` is
``DURATION``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from aeroexec.dialects.tml.reader import (
    TmlArgument,
    TmlBehavior,
    TmlBeliefOperation,
    TmlEvent,
    TmlProgram,
    TmlTask,
    file_bytes,
    is_tml,
    load_tml,
    read_tml,
    read_tml_root,
)
from aeroexec.engine.catalog import BehaviorCatalog, default_catalog
from aeroexec.trees.loaders.xml_loader import parse_xml, read_xml
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode

if TYPE_CHECKING:  # py_trees is loaded when a tree is built to run, not to read or verify one (~15 ms)
    from py_trees.behaviour import Behaviour

VARIABLE_USE = re.compile(r"\+([A-Za-z_]\w*)")
VARIABLE_BINDING = re.compile(r"\?([A-Za-z_]\w*)")
#: Levant behavior names -> (the aerial catalog's name, argument renames).
LEVANT_BEHAVIORS: dict[str, tuple[str, dict[str, str]]] = {
    "REQUEST_OPERATOR_ASSISTANCE": ("ASK_OPERATOR", {"MESSAGE": "QUESTION", "OPTIONS": "POSSIBLE_ANSWERS"}),
    "WAIT": ("WAIT", {"TIMEOUT": "DURATION"}),
}
_BELIEF_LEAF = {"consult": "QueryBelief", "add": "AddBelief", "remove": "RemoveBelief"}


def uses(text: str) -> list[str]:
    """The variables a text reads (``+X``), in order."""
    return VARIABLE_USE.findall(text or "")


def bindings(text: str) -> list[str]:
    """The variables a belief expression binds (``?X``; a bare ``?`` binds nothing)."""
    return VARIABLE_BINDING.findall(text or "")


def to_references(text: str) -> str:
    """``+X`` as the blackboard reference ``{X}`` (``[+X, +Y, 1.5]`` -> ``[{X}, {Y}, 1.5]``)."""
    return VARIABLE_USE.sub(lambda m: "{" + m.group(1) + "}", text)


def free_variables(task: TmlTask) -> list[str]:
    """The variables a task tree uses (``+X``) before a ``<consult>`` of its own binds them, in order."""
    free: list[str] = []
    bound: set[str] = set()
    for sub in task.walk():
        behaviors = [*sub.recurrent, *([sub.work] if isinstance(sub.work, TmlBehavior) else [])]
        texts = [a.value for b in behaviors for a in b.arguments]
        if isinstance(sub.work, TmlBeliefOperation):
            texts.append(sub.work.belief)
        free += [v for text in texts for v in uses(text) if v not in bound and v not in free]
        if isinstance(sub.work, TmlBeliefOperation) and sub.work.kind == "consult":
            bound |= set(bindings(sub.work.belief))
    return free


def behavior_name(name: str) -> str:
    """The catalog name of a behavior as TML writes it (any case; Levant names translated)."""
    upper = name.strip().upper()
    return LEVANT_BEHAVIORS.get(upper, (upper, {}))[0]


def argument_port(behavior: str, argument: str) -> str:
    """The port of a TML argument (upper case; Levant names translated)."""
    upper = argument.strip().upper()
    return LEVANT_BEHAVIORS.get(behavior.strip().upper(), ("", {}))[1].get(upper, upper)


@dataclass
class TmlDocument(TreeDocument):
    """A compiled TML mission: its trees by root task, the main one, and the event handlers.

    ``program`` is the source; ``places`` maps each compiled node (``id``) to its task; ``task_leaves`` are the
    nodes of the leaf tasks doing a behavior in the main tree (where an event can interrupt the mission).
    """

    program: TmlProgram | None = None
    events: list[TmlEvent] = field(default_factory=list)
    places: dict[int, TmlTask] = field(default_factory=dict)
    task_leaves: list[TreeNode] = field(default_factory=list)

    def build(self, context: Any, blackboard: Any) -> Behaviour:
        """The runnable mission: the main tree under the event handling node (see :mod:`.tml_runtime`)."""
        from aeroexec.dialects.tml.runtime import TmlEventHandling
        from aeroexec.trees.runtime.builder import TreeBuilder

        builder = TreeBuilder(self, context)
        main = builder.node(self.root, blackboard, (self.main,))
        called: dict[str, Behaviour] = {}
        for event in self.events:
            if event.call and event.call not in called and event.call in self.trees:
                called[event.call] = builder.node(self.trees[event.call], blackboard, (event.call,))
        name = Path(self.file).name if self.file else self.main
        needs = {call: free_variables(self.program.trees[call]) for call in called} if self.program else {}
        return TmlEventHandling(name, main, called, self.events, context, blackboard, needs)


class _Compiler:
    def __init__(self, program: TmlProgram, catalog: BehaviorCatalog) -> None:
        self.program = program
        self.file = program.file
        self.catalog = catalog
        self.places: dict[int, TmlTask] = {}
        self.leaves: list[TreeNode] = []
        self.problems: list[tuple[str, int, str]] = []

    def node(self, kind: str, name: str, line: int, task: TmlTask, children: list[TreeNode] | None = None,
             **ports: str) -> TreeNode:
        node = TreeNode(kind, name, dict(ports), children or [], self.file, line)
        self.places[id(node)] = task
        return node

    def task(self, task: TmlTask, active: frozenset[str], main: bool) -> TreeNode:
        recurrent = [b for b in task.recurrent if behavior_name(b.name) not in active]
        inner = active | {behavior_name(b.name) for b in task.recurrent}
        if task.work is not None:
            body = self.work(task, task.work, main)
        else:
            children = [self.task(sub, inner, main) for sub in task.subtasks]
            name = f"{task.name}: subtasks" if recurrent else task.name
            body = self.node("SequenceWithMemory", name, task.line, task, children)
        if not recurrent:
            return body
        leaves = [self.behavior(task, b, b.name) for b in recurrent]
        return self.node("Parallel", task.name, task.line, task, [*leaves, body], success_count="1",
                         failure_count="1")

    def work(self, task: TmlTask, work: TmlBehavior | TmlBeliefOperation, main: bool) -> TreeNode:
        if isinstance(work, TmlBeliefOperation):
            return self.node(_BELIEF_LEAF[work.kind], task.name, work.line, task, belief=to_references(work.belief))
        leaf = self.behavior(task, work, task.name)
        if main:
            self.leaves.append(leaf)
        return leaf

    def behavior(self, task: TmlTask, behavior: TmlBehavior, name: str) -> TreeNode:
        ports = {self.argument_name(behavior, a): to_references(a.value) for a in behavior.arguments}
        ports.pop("", None)
        return self.node(behavior_name(behavior.name) or "(no name)", name, behavior.line, task, **ports)

    def argument_name(self, behavior: TmlBehavior, argument: TmlArgument) -> str:
        """The port of an argument; ``<argument value>`` without name is the behavior's only argument."""
        if argument.name:
            return argument_port(behavior.name, argument.name)
        descriptor = self.catalog.behavior(behavior_name(behavior.name))
        if descriptor is None:
            return ""  # the unknown behavior is reported by verification
        if len(descriptor.arguments) == 1:
            return next(iter(descriptor.arguments))
        taken = f"its arguments are {', '.join(descriptor.arguments)}" if descriptor.arguments else "it takes none"
        self.problems.append((self.file, argument.line, f"<argument> without name: the behavior {descriptor.name} "
                                                        f"has not one argument ({taken}): write name=\"...\""))
        return ""


def compile_tml(program: TmlProgram, catalog: BehaviorCatalog | None = None) -> TmlDocument:
    """The tree document of a TML program (verify it with :func:`~.tml_verify.verify_tml`); ``catalog`` (the
    aerial one by default) names the argument an ``<argument>`` without name stands for."""
    compiler = _Compiler(program, catalog if catalog is not None else default_catalog())
    trees = {name: compiler.task(task, frozenset(), name == program.root_task) for name, task in program.trees.items()}
    if compiler.problems:
        raise TreeFormatError(compiler.problems)
    events = [TmlEvent(e.name, e.line, to_references(e.condition), e.condition_line, e.call, e.call_line, e.mode,
                       e.mode_line) for e in program.events]
    lines = {name: task.line for name, task in program.trees.items()}
    return TmlDocument(trees, program.root_task, program.file, lines, program=program, events=events,
                       places=compiler.places, task_leaves=compiler.leaves)


def read_tml_document(data: bytes | str, file: str = "<tml>") -> TmlDocument:
    """A compiled TML mission from XML text."""
    return compile_tml(read_tml(data, file))


def load_tml_document(path: str | Path) -> TmlDocument:
    """A compiled TML mission from a file."""
    return compile_tml(load_tml(path))


def read_tml_element(root: Any, raw: bytes, file: str, lenient: list[tuple[str, int, str]]) -> TmlDocument | None:
    """The TML mission of an XML document whose element ``root`` was read leniently (as BehaviorTree.CPP reads it);
    None when it is no TML mission. The core's XML reader asks it (entry-point group ``aeroexec.xml_documents``)."""
    if not is_tml(root):
        return None
    if lenient:
        root = parse_xml(raw, file)  # TML is read strictly: this says where it stops being XML
    return compile_tml(read_tml_root(root, file))


def read_xml_mission(data: bytes | str, file: str = "<xml>") -> TreeDocument:
    """An XML mission of either kind: TML when the document element is ``<mission>``, else BehaviorTree.CPP v4."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    lenient: list[tuple[str, int, str]] = []
    root = parse_xml(raw, file, lenient)  # as BehaviorTree.CPP reads it (a raw < in an attribute)
    document = read_tml_element(root, raw, file, lenient)
    return document if document is not None else read_xml(raw, file)


def load_xml_mission(path: str | Path) -> TreeDocument:
    """An XML mission file of either kind (see :func:`read_xml_mission`)."""
    return read_xml_mission(file_bytes(path), str(path))
