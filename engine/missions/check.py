"""Static check of Python missions (paper section 6.1): read the program's AST, never run it, and report every
wrong behavior name, argument, literal value and literal belief expression, and impossible sequences, by line.

API calls are found through ``import aeroexec.engine.api as api``, ``from aeroexec.engine import api as X`` and
``from aeroexec.engine.api import executeBehavior [as f]`` (or ``*``), under every alias the API offers, and
the same forms of Aerostack's ``executive_engine_api`` (Levant) and ``mission_execution_control`` (Sirocco).
Predicates a mission adds (``addBelief``) are its own: only expressions over predicates nobody writes are errors.
Values that are not literals (names, calls, f-strings) are left to the run. The entry function is
``mission()``, else ``runMission()``; its sequences are checked by :mod:`.mission_sequence`, unless an API
function or a local function running behaviors is used other than by calling it (stored, passed, ``getattr``).
"""

from __future__ import annotations

import ast
import contextlib
import logging
from pathlib import Path

from aeroexec.beliefs import BeliefError, BeliefMemory, Goal, UnknownPredicateError, parse_belief, parse_rules
from aeroexec.beliefs.expression import BUILTIN_PREDICATES
from aeroexec.engine import api
from aeroexec.engine.catalog import BehaviorCatalog, BehaviorSpecialist
from aeroexec.engine.catalog.arguments import format_value
from aeroexec.engine.catalog.descriptors import RECURRENT, BehaviorDescriptor
from aeroexec.engine.catalog.world_check import WorldMap
from aeroexec.engine.errors import (
    WRONG_FORMAT,
    WRONG_SEQUENCE,
    WRONG_VALUE,
    MissionProblem,
    Problem,
    SpecificationError,
)
from aeroexec.engine.missions.api_modules import (
    API_FUNCTIONS,
    BELIEF,
    NAME_ONLY,
    RUN,
    SEQUENCE,
    api_bindings,
    api_modules,
    foreign,
    module_label,
    offers,
)
from aeroexec.engine.missions.constants import NOT_CONSTANT, Constants, Unknown
from aeroexec.engine.missions.dialect_checks import program_objects, program_problems
from aeroexec.engine.missions.imports import missing_imports
from aeroexec.engine.missions.script import is_script
from aeroexec.engine.missions.sequence import SequenceWalker
from aeroexec.engine.missions.source import parse_source
from aeroexec.engine.yaml_nodes import suggestion

from aeroexec.limits import InputError, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any

logger = logging.getLogger(__name__)

ENTRY_POINTS = ("mission", "runMission")


class MissionChecker:
    """Checks one parsed mission program; ``problems`` collects what it finds."""

    def __init__(self, tree: ast.Module, file: str, specialist: BehaviorSpecialist) -> None:
        self.tree, self.file, self.specialist = tree, file, specialist
        self.catalog = specialist.catalog
        self.constants = Constants(tree)
        self.bindings = api_bindings(self.constants.nodes)
        self.problems: list[MissionProblem] = []
        self._seen: set[tuple[int, int, str]] = set()
        self.nodes, self.parents = self.constants.nodes, self.constants.parents  # the program is walked once
        self.functions: dict[str, list[ast.FunctionDef | ast.AsyncFunctionDef]] = {}
        for node in self.nodes:
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                self.functions.setdefault(node.name, []).append(node)
        self.objects = program_objects(self)  # a dialect's objects that run behaviors: Aerostack2's drones
        self.effectful_functions, self._effectful = self._effects()
        self.vocabulary, self.open_vocabulary = self._vocabulary()

    def _vocabulary(self) -> tuple[dict[str, int], bool]:
        """The catalog's predicates and those the mission adds itself; True when it adds a computed belief
        (whose predicate cannot be known)."""
        vocabulary = {p.name: p.arity for p in self.catalog.predicates.values()}
        computed = False
        for node in self.nodes:
            if isinstance(node, ast.Call) and (self.api_member(node.func) or ("", ""))[1] == "add_rules":
                text = self.value(node.args[0]) if node.args else NOT_CONSTANT  # the predicates its rules derive
                computed = computed or not isinstance(text, str)
                with contextlib.suppress(BeliefError):
                    vocabulary.update({r.head.name: r.head.arity for r in parse_rules(text)} if isinstance(
                        text, str) else {})
            if isinstance(node, ast.Call) and self.api_function(node.func) == "add_belief":
                argument = self.belief_argument(node)
                text = self.value(argument) if argument is not None else NOT_CONSTANT
                if not isinstance(text, str):
                    computed = True
                    continue
                try:
                    belief = parse_belief(text)
                except BeliefError:
                    continue
                vocabulary.setdefault(belief.name, len(belief.args))
        return vocabulary, computed

    def value(self, node: ast.AST) -> Any:
        """The constant an expression stands for (literals, and names bound once to them), or NOT_CONSTANT."""
        return self.constants.value(node)

    @staticmethod
    def belief_argument(call: ast.Call) -> ast.AST | None:
        return call.args[0] if call.args else next(
            (k.value for k in call.keywords if k.arg in ("expression", "belief", "pattern")), None)

    # -- reporting ----------------------------------------------------------------------
    def report(self, node: ast.AST | None, message: str, kind: str = "", severity: str = "error") -> None:
        line = getattr(node, "lineno", 0) or 0
        column = getattr(node, "col_offset", -1) + 1
        if (line, column, message) not in self._seen:
            self._seen.add((line, column, message))
            self.problems.append(MissionProblem(severity, message, self.file, line, kind, column))

    # -- the API ------------------------------------------------------------------------
    def dotted(self, node: ast.AST) -> str | None:
        if isinstance(node, ast.Name):
            return self.bindings.get(node.id)
        if isinstance(node, ast.Attribute):
            base = self.dotted(node.value)
            return f"{base}.{node.attr}" if base else None
        return None

    def api_member(self, node: ast.AST) -> tuple[str, str] | None:
        """The API module and the name an expression has there when it is ``api.X`` or an imported ``X``."""
        path = self.dotted(node)
        for module in api_modules():
            if path and path.startswith(module + ".") and "." not in path[len(module) + 1:]:
                return module, path[len(module) + 1:]
        return None

    def api_name(self, node: ast.AST) -> str | None:
        member = self.api_member(node)
        return member[1] if member else None

    def api_function(self, node: ast.AST) -> str | None:
        member = self.api_member(node)
        return api_modules()[member[0]].get(member[1]) if member else None

    def foreign_call(self, call: ast.Call) -> bool:
        member = self.api_member(call.func)
        return member is not None and foreign(member[0])

    # -- request checks ----------------------------------------------------------------
    def check_program(self) -> None:
        for node in self.nodes:
            if isinstance(node, ast.Attribute):  # imported names are checked at their import
                member = self.api_member(node)
                if member is not None and not offers(*member):
                    module, name = member
                    self.report(node, f"The function {name} does not exist in the mission API{module_label(module)}"
                                      f"{suggestion(name, api_modules()[module])}", WRONG_FORMAT)
            elif isinstance(node, ast.ImportFrom) and node.module in api_modules():
                for alias in node.names:
                    if alias.name != "*" and not offers(node.module, alias.name):
                        known = api_modules()[node.module]
                        self.report(node, f"The function {alias.name} does not exist in the mission API"
                                          f"{module_label(node.module)}{suggestion(alias.name, known)}", WRONG_FORMAT)
            elif isinstance(node, ast.Call):
                function = self.api_function(node.func)
                for objects in self.objects:
                    objects.check(node)
                if function in RUN or function in NAME_ONLY:
                    self.check_behavior_call(node, function)
                elif function in BELIEF:
                    self.check_belief_call(node, function)
                elif function == "wait" and node.args:
                    seconds = self.value(node.args[0])
                    if seconds is not NOT_CONSTANT and not (_is_number(seconds) and seconds >= 0):
                        self.report(node.args[0], f"The value {format_value(seconds)} of wait is not correct "
                                                  f"(a number of seconds, 0 or more, is expected)", WRONG_VALUE)

    def name_node(self, call: ast.Call) -> ast.AST | None:
        """The argument naming the behavior: the first, or ``name=``; for Aerostack's inhibit and deactivate,
        which also take the uid an activation returned, the first text literal (None: stopped by uid)."""
        function = self.api_function(call.func)
        if function == "inhibit_behavior" and self.foreign_call(call):
            given = [*call.args, *(k.value for k in call.keywords if k.arg in ("name", "behavior", "task"))]
            return next((n for n in given if isinstance(self.value(n), str)), None)
        keywords = ("name", "behavior", "task", "planner")
        return call.args[0] if call.args else next((k.value for k in call.keywords if k.arg in keywords), None)

    def behavior_name(self, call: ast.Call) -> str | None:
        """The literal behavior name of a call, upper-cased as the API does; None when it cannot be known."""
        node = self.name_node(call)
        if node is None and self.api_function(call.func) == "inhibit_behavior" and self.foreign_call(call):
            return None  # stopped by the uid its activation returned
        if node is None:
            self.report(call, f"{ast.unparse(call.func)}() needs the name of a behavior", WRONG_FORMAT)
            return None
        value = self.value(node)
        if value is NOT_CONSTANT:
            self.report(node, f"The behavior name is computed ({ast.unparse(node)}): the behavior and its "
                              f"arguments are checked only when the mission runs", severity="warning")
            return None
        return str(value).upper()

    def request(self, call: ast.Call, descriptor: BehaviorDescriptor
                ) -> tuple[dict[str, Any], set[str], bool, dict[str, ast.AST]]:
        """Catalog-cased arguments (opaque where not literal), the opaque names, whether ``**`` is used, nodes."""
        known = {alias.upper(): a.name for a in descriptor.arguments.values() for alias in (a.name, *a.aliases)}
        arguments: dict[str, Any] = {}
        opaque: set[str] = set()
        nodes: dict[str, ast.AST] = {}
        star = False
        for keyword in call.keywords:
            if keyword.arg is None:
                star = True
            elif keyword.arg not in api.RESERVED and keyword.arg not in ("name", "behavior", "task", "planner"):
                key = known.get(keyword.arg.upper(), keyword.arg.upper())
                value = self.value(keyword.value)
                nodes[key] = keyword.value
                if value is NOT_CONSTANT:
                    opaque.add(key)
                    value = Unknown()
                arguments[key] = value
        return arguments, opaque, star, nodes

    def check_behavior_call(self, call: ast.Call, function: str) -> None:
        name = self.behavior_name(call)
        if name is None:
            return
        descriptor = self.catalog.behavior(name)
        name_node = self.name_node(call) or call
        if descriptor is None:
            self.report(name_node, f"The behavior {name} does not exist{self.catalog.suggest(name)}", WRONG_FORMAT)
            return
        if len(call.args) > 1 and not (function in NAME_ONLY and self.foreign_call(call)):
            self.report(call.args[1], f"{ast.unparse(call.func)}() takes the behavior name, then its arguments "
                                      f"by name (argument=value)", WRONG_FORMAT)
        if function in NAME_ONLY:
            return
        arguments, opaque, star, nodes = self.request(call, descriptor)
        for error in self.specialist.request_errors(name, arguments):
            about = [k for k in nodes if f"argument {k} of " in error.message or f"argument {k} for " in error.message]
            if (error.kind == WRONG_VALUE and any(k in opaque for k in about)) or (star and not about):
                continue
            self.report(nodes[about[0]] if about else call, error.message, error.kind)
        given = {k.arg: k.value for k in call.keywords if k.arg in api.RESERVED}
        timeout = self.value(given["timeout"]) if "timeout" in given else NOT_CONSTANT
        if timeout is not NOT_CONSTANT and not (_is_number(timeout) and timeout > 0):
            self.report(given["timeout"], f"The value {format_value(timeout)} of argument timeout for behavior "
                                          f"{name} is not correct (a positive number of seconds is expected)",
                        WRONG_VALUE)
        if function != "activate_behavior" and descriptor.category == RECURRENT and "timeout" not in given \
                and not star:
            self.report(call, f"The behavior {name} is recurrent: it has no goal to wait for "
                              f"(use activate_behavior, or give timeout=)", WRONG_FORMAT)

    def check_belief_call(self, call: ast.Call, function: str) -> None:
        node = self.belief_argument(call)
        text = self.value(node) if node is not None else NOT_CONSTANT
        if text is NOT_CONSTANT:
            return
        if not isinstance(text, str):
            self.report(node, f"The format of the belief expression {format_value(text)} is not correct "
                              f"(a belief expression is text)", WRONG_FORMAT)
            return
        try:
            expression = BeliefMemory(predicates=self.vocabulary).check(text)
            if function == "add_belief":
                belief = parse_belief(text)
                declared = self.catalog.predicates.get(belief.name)
                if (declared is not None and declared.computed) or belief.signature in BUILTIN_PREDICATES:
                    raise BeliefError(f"{belief.name} is computed by the engine and cannot be stored as a belief")
            else:
                for message in self.specialist.unwritten_values(expression):
                    self.report(node, message, WRONG_VALUE, "warning")
            if function == "remove_belief" and (len(expression.literals) != 1
                                                  or type(expression.literals[0]) is not Goal):
                raise BeliefError(f"The format of the belief expression {text} is not correct "
                                  f"(expected a single predicate such as visible(?X))")
        except UnknownPredicateError as exc:
            if self.open_vocabulary:  # the mission adds beliefs it computes: this predicate may be one of them
                self.report(node, f"{exc.message} (unless the mission adds it with a computed belief)",
                            WRONG_FORMAT, "warning")
            else:
                self.report(node, exc.message, WRONG_FORMAT)
        except (SpecificationError, BeliefError) as exc:
            self.report(node, exc.message, WRONG_FORMAT)

    # -- sequences ------------------------------------------------------------------------
    def behavior_requests(self, call: ast.Call, state: Mapping[str, Any] | None = None,
                          ) -> list[tuple[str, str | None, dict[str, Any], set[str]]]:
        """For a call that runs or inhibits behaviors (an API function, or a drone interface's module), each
        request: the API function, the behavior name (None when not known), its catalog-cased arguments and the
        names of those not known (``**`` for ``**kwargs``); empty for any other call. ``state``: the phenomena's
        states where the call is made (None when not walking the program), which a dialect's objects may ask
        (a rule of an earlier era of their API that depends on the flight state)."""
        function = self.api_function(call.func)
        if function not in SEQUENCE:
            return [request for objects in self.objects for request in objects.sequence_requests(call, state)]
        node = self.name_node(call)
        name = self.value(node) if node is not None else NOT_CONSTANT
        if not isinstance(name, str):
            return [(function, None, {}, set())]
        descriptor = self.catalog.behavior(name.upper())
        if descriptor is None:
            return [(function, name.upper(), {}, set())]
        arguments, opaque, star, _ = self.request(call, descriptor)
        return [(function, name.upper(), arguments, opaque | ({"**"} if star else set()))]

    def calls_local_behaviors(self, call: ast.Call) -> bool:
        """True when ``call`` calls one of the program's functions that run or inhibit behaviors."""
        return _called_name(call) in self.effectful_functions

    def local_function(self, call: ast.Call) -> ast.FunctionDef | ast.AsyncFunctionDef | None:
        """The program's top-level function a plain call runs (None for a method, or a name defined twice)."""
        if not isinstance(call.func, ast.Name) or len(self.functions.get(call.func.id, ())) != 1:
            return None
        function = self.functions[call.func.id][0]
        return function if function in self.tree.body else None

    def _effects(self) -> tuple[set[str], set[int]]:
        """The names of the program's functions that run or inhibit behaviors, directly or through each other,
        and every node that holds such a call (in one pass over the program, then up the parents)."""
        calls = [n for n in self.nodes if isinstance(n, ast.Call)]
        direct = [c for c in calls if self.api_function(c.func) in SEQUENCE
                  or any(objects.runs_behaviors(c) for objects in self.objects)]
        within: dict[int, list[str]] = {}  # id(call) -> the names of the functions around it

        def functions_around(call: ast.Call) -> list[str]:
            if id(call) not in within:
                names, node = [], self.parents.get(id(call))
                while node is not None:
                    if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                        names.append(node.name)
                    node = self.parents.get(id(node))
                within[id(call)] = names
            return within[id(call)]

        effectful = {name for call in direct for name in functions_around(call)}
        callers: dict[str, set[str]] = {}  # called name -> the functions whose bodies call it
        for call in calls:
            name = _called_name(call)
            if name is not None:
                callers.setdefault(name, set()).update(functions_around(call))
        waiting = list(effectful)
        while waiting:
            for caller in callers.get(waiting.pop(), ()):
                if caller not in effectful:
                    effectful.add(caller)
                    waiting.append(caller)
        marked: set[int] = set()
        for call in [*direct, *(c for c in calls if _called_name(c) in effectful)]:
            node: ast.AST | None = call
            while node is not None and id(node) not in marked:
                marked.add(id(node))
                node = self.parents.get(id(node))
        return effectful, marked

    def effectful(self, node: ast.AST) -> bool:
        """True when ``node`` holds a call that runs or inhibits behaviors."""
        return id(node) in self._effectful

    def sequence_checkable(self) -> bool:
        """False when behaviors may run through a reference the checker cannot follow (stored, passed, getattr),
        or on several drones (each has its own flight)."""
        if any(objects.several for objects in self.objects):
            return False
        followed = {id(n.func) for n in self.nodes if isinstance(n, ast.Call)}
        followed |= {id(n.value) for n in self.nodes if isinstance(n, ast.Attribute)}
        for node in self.nodes:
            if isinstance(node, ast.Name | ast.Attribute) and id(node) not in followed:
                function = self.api_function(node)
                if function in SEQUENCE or self.dotted(node) in api_modules():
                    return False
                if isinstance(node, ast.Name) and node.id in self.effectful_functions:
                    return False
        return True


#: The calls that end a program from inside a loop.
EXITS = ("sys.exit", "exit", "quit", "os._exit")


def endless_loops(checker: MissionChecker) -> list[ast.While]:
    """The ``while True:`` loops of a script with no way out (no ``break`` of their own, ``return``, ``raise`` or
    exit call, outside the functions and classes they define) that the flight reaches: at the script's top level,
    or in a function that runs behaviors (a thread's loop that never commands the drone is left alone)."""
    endless = []
    for loop in checker.nodes:
        if not (isinstance(loop, ast.While) and isinstance(loop.test, ast.Constant) and loop.test.value):
            continue
        around = checker.parents.get(id(loop))
        while around is not None and not isinstance(around, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            around = checker.parents.get(id(around))
        if around is not None and not checker.effectful(loop) and around.name not in checker.effectful_functions:
            continue
        if not any(_leaves(statement, checker) for statement in loop.body):
            endless.append(loop)
    return endless


def sibling_problems(tree: ast.Module, filename: str, specialist: BehaviorSpecialist,
                     seen: set[Path] | None = None) -> list[MissionProblem]:
    """What is wrong in the modules of a script's folder that it imports (``from mission.follow_drone_module
    import FollowDroneModule``), at their own file and line: ROS 2 used beyond the drone interface, a drone
    interface's call Aerostack2 does not have; found before flight as in the script itself, not when the module
    is first used in flight."""
    here = Path(filename).resolve().parent if filename and not filename.startswith("<") else None
    seen = seen if seen is not None else {Path(filename).resolve()} if here is not None else set()
    found: list[MissionProblem] = []
    for node in ast.walk(tree) if here is not None else ():
        names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                 [node.module] if isinstance(node, ast.ImportFrom) and node.module and not node.level else [])
        for name in names:
            parts = name.split(".")
            for path in (here.joinpath(*parts).with_suffix(".py"), here.joinpath(*parts, "__init__.py")):
                if path.is_file() and path.resolve() not in seen:
                    seen.add(path.resolve())
                    found += _module_problems(path, specialist, seen)
    return found


def _module_problems(path: Path, specialist: BehaviorSpecialist, seen: set[Path]) -> list[MissionProblem]:
    try:
        tree = parse_source(read_text(path, what="the module"), str(path))
    except (SyntaxError, InputError, ValueError):
        return []  # the run says so when it imports it, as Python does
    checker = MissionChecker(tree, str(path), specialist)
    for node, severity, message in program_problems(checker.nodes, checker.dotted):
        checker.report(node, message, WRONG_FORMAT if severity == "error" else "", severity)
    for node in checker.nodes:
        if isinstance(node, ast.Call):
            for objects in checker.objects:
                objects.check(node)
    return [*checker.problems, *sibling_problems(tree, str(path), specialist, seen)]


def missing_reads(checker: MissionChecker) -> list[tuple[ast.AST, str]]:
    """The files a script opens for reading that are not there: ``open("config/joints.csv")``, or ``open(path)``
    in a function of the script called with that name (``load_path_from_csv("config/joints.csv")``); relative
    names are read from the current folder, as under ``python3``. Each with the node that names it."""
    found: list[tuple[ast.AST, str]] = []
    for call in checker.nodes:
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == "open"
                and call.args and "open" not in checker.functions):
            continue
        mode = checker.value(call.args[1]) if len(call.args) > 1 else next(
            (checker.value(k.value) for k in call.keywords if k.arg == "mode"), "r")
        if not isinstance(mode, str) or not set(mode) & {"r"} or set(mode) & {"w", "a", "x", "+"}:
            continue
        for node in _named_files(checker, call.args[0]):
            name = checker.value(node)
            if isinstance(name, str) and name and not Path(name).expanduser().exists():
                found.append((node, name))
    return found


def _named_files(checker: MissionChecker, argument: ast.AST) -> list[ast.AST]:
    """The nodes that give ``argument`` its value: itself, or, for a parameter of the function it is in, the
    arguments that parameter gets at each call of that function in the program."""
    if not isinstance(argument, ast.Name):
        return [argument]
    around = checker.parents.get(id(argument))
    while around is not None and not isinstance(around, ast.FunctionDef | ast.AsyncFunctionDef):
        around = checker.parents.get(id(around))
    parameters = [a.arg for a in around.args.args] if around is not None else []
    if argument.id not in parameters or len(checker.functions.get(around.name, ())) != 1:
        return [argument]
    index, given = parameters.index(argument.id), []
    for call in checker.nodes:
        if isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == around.name:
            keyword = next((k.value for k in call.keywords if k.arg == argument.id), None)
            given += [call.args[index]] if index < len(call.args) else [keyword] if keyword is not None else []
    return given


def _leaves(node: ast.AST, checker: MissionChecker, nested_loop: bool = False) -> bool:
    """True when ``node`` may leave the loop it is in (``nested_loop``: within an inner loop, whose ``break``
    leaves that one only)."""
    if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef | ast.Lambda):
        return False
    if isinstance(node, ast.Return | ast.Raise) or (isinstance(node, ast.Break) and not nested_loop):
        return True
    if isinstance(node, ast.Call) and checker.dotted(node.func) in EXITS:
        return True
    inner = nested_loop or isinstance(node, ast.For | ast.AsyncFor | ast.While)
    return any(_leaves(child, checker, inner) for child in ast.iter_child_nodes(node))


def _called_name(call: ast.Call) -> str | None:
    func = call.func
    return func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else None


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def check_mission_source(source: str, filename: str, catalog: BehaviorCatalog | None = None,
                         world: WorldMap | None = None) -> list[Problem]:
    """Every problem of a mission program, by line: request errors, belief expressions, sequences; with a
    ``world``, literal destinations and paths against its bounds and obstacles."""
    try:
        tree = parse_source(source, filename)
    except SyntaxError as exc:  # a NUL byte has no line from Python: it is found here
        line = exc.lineno or (source.count("\n", 0, source.find("\0")) + 1 if "\0" in source else 0)
        return [MissionProblem("error", f"The mission is not valid Python: {exc.msg}", filename, line,
                               WRONG_FORMAT, max(exc.offset or 0, 0) if exc.lineno else 0)]  # f-strings: < 0
    checker = MissionChecker(tree, filename, BehaviorSpecialist(catalog, world))
    missing = missing_imports(tree, filename)
    for statement, module in missing:
        checker.report(statement, f"The module {module} cannot be found: the mission would stop at this import",
                       WRONG_FORMAT)
    for node, severity, message, *kind in program_problems(checker.nodes, checker.dotted):  # a dialect's: ROS used
        checker.report(node, message, (kind[0] if kind else WRONG_FORMAT) if severity == "error" else "", severity)
    checker.check_program()
    entries = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name in ENTRY_POINTS}
    entry = next((entries[name] for name in ENTRY_POINTS if name in entries), None)
    if entry is None and is_script(tree, checker.nodes):  # a script (Aerostack2's): it runs whole, from its start
        for loop in endless_loops(checker):
            checker.report(loop, "This mission never ends: the loop `while True:` has no break, return or exit, so "
                                 "the drone would fly on until the battery runs low; "
                                 "give the loop an end (a count, a duration or a condition)", WRONG_SEQUENCE)
        checker.problems.extend(sibling_problems(tree, filename, checker.specialist))
        for node, name in missing_reads(checker):
            checker.report(node, f"The script reads the file {name}, which is not there (from the folder "
                                 f"{Path.cwd()}): the mission would stop at this line; run it from the folder "
                                 f"that holds {name}, as under python3", WRONG_FORMAT)
        if checker.sequence_checkable():
            SequenceWalker(checker).check_body(tree.body)
    elif entry is None:
        modules = list(dict.fromkeys(m.partition(".")[0] for _, m in missing))
        foreign = (f", and imports no mission API that runs scripts whole: a program for other software, whose "
                   f"modules {', '.join(modules)} cannot be found here" if modules else "")
        checker.problems.append(MissionProblem("error", f"The mission has no mission() or runMission() "
                                                        f"function{foreign}", filename, 0, WRONG_FORMAT))
    elif entry.args.args[len(entry.args.defaults):] or entry.args.posonlyargs or [
            a for a, d in zip(entry.args.kwonlyargs, entry.args.kw_defaults, strict=True) if d is None]:
        checker.report(entry, f"The function {entry.name}() is called without arguments: it cannot require any",
                       WRONG_FORMAT)
    elif checker.sequence_checkable():
        SequenceWalker(checker).check(entry)
    else:
        logger.info("%s: behaviors are run through references; sequences are not checked", filename)
    checker.problems.sort(key=lambda p: (p.line, p.column))
    return list(checker.problems)


def literal_requests(source: str, filename: str, catalog: BehaviorCatalog | None = None
                     ) -> list[tuple[str, dict[str, Any], int]]:
    """Every behavior a program asks for, in the order written: ``(behavior, arguments, line)`` with the arguments
    named as the catalog names them, whatever the mission wrote (``coordinates=``, ``point=``, an Aerostack2
    drone interface's positional ``go_to(x, y, z)``), each value the constant it is or :class:`Unknown` when it is
    known only in flight. The safety rules' check before flight reads its destinations from here."""
    try:
        tree = parse_source(source, filename)
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return []  # the mission's check reports it
    checker = MissionChecker(tree, filename, BehaviorSpecialist(catalog))
    calls = sorted((n for n in checker.nodes if isinstance(n, ast.Call)), key=lambda n: (n.lineno, n.col_offset))
    found = []
    for call in calls:
        for function, name, arguments, _ in checker.behavior_requests(call):
            if function in RUN and name is not None:
                found.append((name, arguments, call.lineno))
    return found


def check_mission_file(path: str | Path, catalog: BehaviorCatalog | None = None) -> list[Problem]:
    """Read and check a mission file (see :func:`check_mission_source`)."""
    path = Path(path)
    try:
        source = read_text(path)
    except InputError as exc:
        return [MissionProblem("error", f"The mission cannot be read: {exc.message}", exc.file, exc.line)]
    return check_mission_source(source, str(path), catalog)


__all__ = ["API_FUNCTIONS", "ENTRY_POINTS", "MissionChecker", "MissionProblem", "check_mission_file",
           "check_mission_source", "literal_requests"]
