"""The static check of Aerostack2 scripts: which expressions are drone interfaces, and what their calls ask for.

A drone interface is a name bound to ``DroneInterface(...)`` (or ``DroneInterfaceBase``, ``DroneInterfaceGPS``,
``DroneInterfaceTeleop``, or a class of the script's own derived from one), a parameter annotated with one
(``def drone_run(drone_interface: DroneInterface)``), ``self`` in such a class, or a mission interpreter's
``.drone``. ``uav.takeoff(...)``, ``uav.go_to.go_to_point(...)`` and the like are bound as Aerostack2 binds them
and turned into catalog requests (:mod:`.aerostack2`), which the checker judges as any other request; a method
Aerostack2 does not have is an error, as is a call of the ROS 2 node a drone interface also is.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from aeroexec.dialects.aerostack2 import behaviors as aerostack2
from aeroexec.dialects.aerostack2 import eras
from aeroexec.dialects.aerostack2.behaviors import As2Error, Method, Request
from aeroexec.dialects.ros import ROS2_BEYOND
from aeroexec.engine.catalog import BehaviorSpecialist
from aeroexec.engine.errors import WRONG_FORMAT, WRONG_VALUE
from aeroexec.engine.missions.constants import NOT_CONSTANT, Constants, Unknown
from aeroexec.engine.yaml_nodes import suggestion


class MissionChecker(Protocol):
    """What this module uses of the mission's checker (:class:`~aeroexec.engine.missions.check.MissionChecker`)."""

    tree: ast.Module
    nodes: list[ast.AST]
    parents: dict[int, ast.AST]
    constants: Constants
    specialist: BehaviorSpecialist

    def dotted(self, node: ast.AST) -> str | None: ...
    def value(self, node: ast.AST) -> Any: ...
    def report(self, node: ast.AST | None, message: str, kind: str = "", severity: str = "error") -> None: ...

#: Aerostack2's Python API, by its names: ``as2_python_api``, and ``python_interface``: Aerostack2 before 1.0 (the
#: package was renamed as2_python_api in December 2022).
APIS = ("as2_python_api.", "python_interface.")
_INTERPRETER = "MissionInterpreter"
#: The beginnings of a ROS 2 node's own methods: on a drone interface they use ROS 2 beyond it.
NODE_API = ("create_", "destroy_", "declare_", "get_parameter", "set_parameters", "has_parameter", "get_clock",
            "add_on_set_parameters_callback", "wait_for_")
#: Where the argument that made a catalog argument is, to point at it: catalog argument -> Aerostack2 parameters.
_SOURCES = {"ALTITUDE": ("height",), "COORDINATES": ("point", "waypoint", "x", "_x", "lat", "height"),
            "SPEED": ("speed", "speed_x"), "PATH": ("path", "geopath"), "YAW_ANGLE_AT_THE_END": ("angle", "yaw_angle")}


#: A string that names a frame of ROS 2's tf tree (``gate_0/link``, ``drone0/base_link``, ``cf0/odom``).
TF_FRAME = re.compile(r"^/?[A-Za-z_]\w*(/\w+)*/\w*(link|frame|odom|map|footprint)$")


@dataclass
class DroneClass:
    """What a drone interface expression is: its Aerostack2 interface and, for a class of the script's own, the
    names that class defines."""

    interface: str
    own: set[str] = field(default_factory=set)
    any_module: bool = False  # a mission interpreter's drone: it loads the modules its plan needs

    def modules(self, loaded: set[str]) -> dict[str, str]:
        return {**aerostack2.INTERFACES.get(self.interface, {}), **{m: m for m in loaded}}


@dataclass
class As2Call:
    """A call of a behavior module: its method, the node of each argument given, and the bound values."""

    call: ast.Call
    method: Method
    nodes: dict[str, ast.AST]
    bound: dict[str, Any] | None  # None: not bindable before flight (``*args``, ``**kwargs``), or wrongly called
    error: As2Error | None = None  # why it cannot be bound (a call Python would refuse)


class DroneObjects:
    """Finds drone interfaces and their calls in one program (through the checker's imports and constants)."""

    def __init__(self, checker: MissionChecker) -> None:
        self.checker = checker
        self.classes: dict[str, DroneClass] = {}  # the script's own classes derived from a drone interface
        self.names: dict[str, DroneClass] = {}  # names bound to a drone interface
        self.interpreters: set[str] = set()  # names bound to a mission interpreter
        self.loaded: set[str] = set()  # modules loaded with load_module("...")
        self.constructions: list[ast.Call] = []  # where drone interfaces are made
        #: python_interface's era, an armed drone: a follow_path from the ground takes off by its path (.eras)
        self.takes_off_by_path = eras.imports_era_api(checker.nodes) is not None and eras.arms(checker.nodes)
        self.annotated: dict[int, dict[str, DroneClass]] = {}  # id(function) -> parameter -> class
        self.methods_of: dict[int, DroneClass] = {}  # id(function) -> the class whose method it is
        self._found: dict[int, As2Call | None] = {}
        #: The strings of the program that name frames of ROS 2's tf tree and are data (in a list, a dict, bound
        #: to a name: not an argument given straight to a call, which is judged where it is given), in order.
        self.tf_frames = sorted((n for n in checker.nodes if isinstance(n, ast.Constant) and isinstance(n.value, str)
                                 and TF_FRAME.match(n.value)
                                 and not isinstance(checker.parents.get(id(n)), ast.keyword | ast.Call)),
                                key=lambda n: (n.lineno, n.col_offset))
        for node in checker.nodes:
            if isinstance(node, ast.ClassDef):
                self._class(node)
        for node in checker.nodes:
            if isinstance(node, ast.Call):
                made = self.constructed(node)
                if made is not None:
                    self.constructions.append(node)
                elif self._imported(node.func, _INTERPRETER):
                    pass
                elif isinstance(node.func, ast.Attribute) and node.func.attr == "load_module" and node.args:
                    loaded = checker.value(node.args[0])
                    if isinstance(loaded, str):
                        self.loaded.add(loaded.rsplit(".", 1)[-1].removesuffix("_module"))
            elif isinstance(node, ast.Assign | ast.AnnAssign) and node.value is not None:
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                made = self.constructed(node.value) if isinstance(node.value, ast.Call) else None
                interpreter = isinstance(node.value, ast.Call) and self._imported(node.value.func, _INTERPRETER)
                for target in targets:
                    if isinstance(target, ast.Name) and made is not None:
                        self.names[target.id] = made
                    elif isinstance(target, ast.Name) and interpreter:
                        self.interpreters.add(target.id)
            elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                parameters = {a.arg: self.annotation(a.annotation) for a in (*node.args.posonlyargs, *node.args.args,
                                                                               *node.args.kwonlyargs)}
                self.annotated[id(node)] = {k: v for k, v in parameters.items() if v is not None}

        self._passed_drones()

    def _passed_drones(self) -> None:
        """A function's parameter with no annotation that every call of the function (at least one, by the
        function's name) gives a drone interface is one (``def drone_run(drone_interface): ...`` called as
        ``drone_run(uav)``): its calls are checked as the drone's."""
        functions = {n.name: n for n in self.checker.tree.body if isinstance(n, ast.FunctionDef)}
        calls: dict[str, list[ast.Call]] = {}
        for node in self.checker.nodes:
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in functions:
                calls.setdefault(node.func.id, []).append(node)
        for name, found in calls.items():
            function = functions[name]
            own = self.annotated.setdefault(id(function), {})
            positional = [*function.args.posonlyargs, *function.args.args]
            for index, parameter in enumerate(positional):
                if parameter.annotation is not None or parameter.arg in own:
                    continue
                given = [next((k.value for k in c.keywords if k.arg == parameter.arg), None) if index >= len(c.args)
                         else c.args[index] for c in found]
                if any(g is None or isinstance(g, ast.Starred) for g in given):
                    continue
                drones = [self.drone(g) for g in given]
                if drones[0] is not None and all(d == drones[0] for d in drones):
                    own[parameter.arg] = drones[0]

    # -- what is a drone interface ------------------------------------------------------------------------
    def _imported(self, node: ast.AST, name: str) -> bool:
        path = self.checker.dotted(node)
        return bool(path) and path.startswith(APIS) and path.rsplit(".", 1)[-1] == name

    def drone_class(self, node: ast.AST | None) -> DroneClass | None:
        """The drone interface class an expression names (imported from as2_python_api, or the script's own)."""
        if node is None:
            return None
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            node = ast.Name(node.value)
        if isinstance(node, ast.Name) and node.id in self.classes:
            return self.classes[node.id]
        path = self.checker.dotted(node) if isinstance(node, ast.Name | ast.Attribute) else None
        if path and path.startswith(APIS):
            interface = path.rsplit(".", 1)[-1]
            if interface in aerostack2.INTERFACES:
                return DroneClass(interface)
        return None

    def annotation(self, node: ast.AST | None) -> DroneClass | None:
        if isinstance(node, ast.Subscript):  # Optional[DroneInterface], List[...] are not one drone
            return None
        return self.drone_class(node)

    def _class(self, node: ast.ClassDef) -> None:
        for base in node.bases:
            found = self.drone_class(base)
            if found is not None:
                own = {n.name for n in node.body if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)}
                own |= {t.attr for n in ast.walk(node) for t in _targets(n)
                        if isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name) and t.value.id == "self"}
                mine = DroneClass(found.interface, found.own | own)
                self.classes[node.name] = mine
                for function in node.body:
                    if isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
                        self.methods_of[id(function)] = mine
                return

    def constructed(self, call: ast.AST) -> DroneClass | None:
        return self.drone_class(call.func) if isinstance(call, ast.Call) else None

    def drone(self, node: ast.AST) -> DroneClass | None:
        """The drone interface an expression is, when the check can tell."""
        if isinstance(node, ast.Name):
            function = self.checker.constants.scope_of.get(id(node))
            own = self.annotated.get(id(function), {})
            if node.id in own:
                return own[node.id]
            if node.id == "self" and id(function) in self.methods_of:
                return self.methods_of[id(function)]
            return self.names.get(node.id)
        if isinstance(node, ast.Attribute) and node.attr == "drone" and isinstance(node.value, ast.Name) \
                and node.value.id in self.interpreters:
            return DroneClass("DroneInterfaceBase", any_module=True)
        return None

    @property
    def several(self) -> bool:
        """True when the script may drive more than one drone (two constructions, or one in a loop)."""
        if len(self.constructions) > 1:
            return True
        loops = (ast.For, ast.AsyncFor, ast.While, ast.ListComp, ast.DictComp, ast.GeneratorExp, ast.SetComp)
        node = self.checker.parents.get(id(self.constructions[0])) if self.constructions else None
        while node is not None:
            if isinstance(node, loops):
                return True
            node = self.checker.parents.get(id(node))
        return False

    # -- calls --------------------------------------------------------------------------------------------
    def runs_behaviors(self, call: ast.Call) -> bool:
        """True when ``call`` is a drone interface's call that runs or stops behaviors."""
        return self.as2_call(call) is not None

    def as2_call(self, call: ast.Call, report: bool = False) -> As2Call | None:
        """The module call ``call`` is (``uav.takeoff(...)``, ``uav.go_to.go_to_point(...)``), else None. With
        ``report``, a method Aerostack2 does not have and a ROS 2 node call are reported."""
        if not report and id(call) in self._found:
            return self._found[id(call)]
        found = self._as2_call(call, report)
        self._found[id(call)] = found
        return found

    def _as2_call(self, call: ast.Call, report: bool) -> As2Call | None:
        func = call.func
        if not isinstance(func, ast.Attribute):
            return None
        owner = self.drone(func.value)
        if owner is not None:
            modules = owner.modules(self.loaded)
            if func.attr in modules and func.attr not in owner.own:
                return self._bind(call, aerostack2.method(modules[func.attr]), f"{owner.interface}.{func.attr}")
            if func.attr in modules or func.attr in owner.own or func.attr in aerostack2.DRONE_MEMBERS:
                return None
            if report:
                self._unknown(func, owner, owner.modules(self.loaded), call)
            return None
        if isinstance(func.value, ast.Attribute):
            owner = self.drone(func.value.value)
            if owner is None or func.value.attr in owner.own:
                return None
            modules = owner.modules(self.loaded)
            alias = modules.get(func.value.attr)
            if alias is None and report and func.value.attr not in aerostack2.DRONE_MEMBERS:
                self._unknown(func.value, owner, modules)
            if alias is None or alias not in aerostack2.MODULES:
                return None
            methods = aerostack2.MODULES[alias]
            if func.attr in methods:
                return self._bind(call, methods[func.attr])
            if report and func.attr not in aerostack2.HANDLER_MEMBERS:
                self.checker.report(func, f"The method {func.attr} does not exist in Aerostack2's {alias} module"
                                          f"{suggestion(func.attr, methods)}", WRONG_FORMAT)
        return None

    def _unknown(self, func: ast.Attribute, owner: DroneClass, modules: dict[str, str],
                 call: ast.Call | None = None) -> None:
        name = func.attr
        if name.startswith(NODE_API):
            self.checker.report(func, f"{owner.interface}.{name}: {ROS2_BEYOND}{_topic_of(func, call)}", WRONG_FORMAT)
        elif not owner.own and not owner.any_module:
            self.checker.report(func, f"The function {name} does not exist in Aerostack2's {owner.interface}"
                                      f"{suggestion(name, (*modules, *aerostack2.DRONE_MEMBERS))}", WRONG_FORMAT)

    def _bind(self, call: ast.Call, method: Method, written: str = "") -> As2Call:
        """``call`` bound to ``method``; ``written``: the drone interface's member the script called, when its name
        is not the module's (a DroneInterfaceGPS's ``follow_path`` is Aerostack2's ``follow_path_gps`` module)."""
        nodes: dict[str, ast.AST] = dict(zip(method.parameters, call.args, strict=False))
        nodes.update({method.named(k.arg): k.value for k in call.keywords if k.arg})
        if any(isinstance(a, ast.Starred) for a in call.args) or any(k.arg is None for k in call.keywords):
            return As2Call(call, method, nodes, None)
        values = [self._value(a) for a in call.args]
        try:
            bound = method.bind(values, {k.arg: self._value(k.value) for k in call.keywords})
        except As2Error as error:
            member = written.rpartition(".")[2]
            if member and member != method.module and error.message.startswith(f"{method.spelled}()"):
                error = As2Error(error.kind, f"{member}() ({written} is Aerostack2's {method.module} module)"
                                             f"{error.message.removeprefix(f'{method.spelled}()')}")
            return As2Call(call, method, nodes, None, error)
        return As2Call(call, method, nodes, bound)

    def _value(self, node: ast.AST) -> Any:
        value = self.checker.value(node)
        return Unknown() if value is NOT_CONSTANT else value

    def requests(self, found: As2Call, report: bool = False) -> list[Request] | None:
        """The catalog requests of a bound call (None when they cannot be known before flight)."""
        if found.bound is None:
            if report and found.error is not None:
                self.checker.report(found.call, found.error.message, found.error.kind)
            return None
        world = self.checker.specialist.world
        home = getattr(world, "home", None)
        try:
            return aerostack2.requests(found.method, found.bound, home=tuple(home) if home is not None else None,
                                       frames=self.world_frames)
        except As2Error as error:
            if report:
                self.checker.report(found.call, error.message, error.kind)
            return None

    def check(self, call: ast.Call) -> None:
        """Report what is wrong with a call of a drone interface: the method, its arguments, each request."""
        found = self.as2_call(call, report=True)
        if found is None:
            return
        self._check_frame(found)
        specialist = self.checker.specialist
        for request in self.requests(found, report=True) or ():
            for error in specialist.request_errors(request.behavior, request.arguments):
                about = [k for k in request.arguments
                         if f"argument {k} of " in error.message or f"argument {k} for " in error.message]
                if error.kind == WRONG_VALUE and any(unknown(request.arguments[k]) for k in about):
                    continue
                self.checker.report(self.node_of(found, about[0]) if about else call, error.message, error.kind)

    def _check_frame(self, found: As2Call) -> None:
        """A frame the check cannot know, in a program that names frames of ROS 2's tf tree: one of those, which
        the run would refuse at this call in flight; refused here, before the drone takes off."""
        frame = (found.bound or {}).get("frame_id")
        known_frames = {f.name for f in self.world_frames}
        unknown_frames = [n for n in self.tf_frames if n.value.strip().lstrip("/") not in known_frames]
        if not isinstance(frame, Unknown) or not unknown_frames:
            return  # every frame the script names is one of the world's: the run places its points
        named = ", ".join(f"{n.value!r} (line {n.lineno})" for n in unknown_frames[:3])
        if known_frames:
            world = getattr(self.checker.specialist.world, "name", "the world")
            what = (f") that are not frames of the world ({', '.join(sorted(known_frames))}: {world}): aeroexec "
                    f"flies in the earth frame (local ENU from home) and its world's frames; other frames")
        else:
            what = "): aeroexec flies in the earth frame (local ENU from home); frames"
        self.checker.report(found.nodes.get("frame_id", found.call),
                            f"The frame of {found.method.spelled}() is not known before flight, and the script names "
                            f"frames of ROS 2's tf tree ({named}{what} of ROS 2's tf tree are not available "
                            f"({ROS2_BEYOND})", WRONG_VALUE)

    @property
    def world_frames(self) -> tuple[Any, ...]:
        """The named frames of the world the program is checked against (a simulator world's models)."""
        return tuple(getattr(self.checker.specialist.world, "frames", ()) or ())

    def sequence_requests(self, call: ast.Call, state: Mapping[str, Any] | None = None,
                          ) -> list[tuple[str, str | None, dict[str, Any], set[str]]]:
        """What the flight-order check needs of a drone interface's call (empty when it asks for no behavior),
        made where the phenomena are in ``state``: a script of python_interface's era that arms its drone takes off
        by a follow_path made on the ground (:mod:`.eras`)."""
        found = self.as2_call(call)
        if found is None:
            return []
        requests = self.requests(found)
        if requests is None:
            return [("execute_behavior", None, {}, set())]
        if self.takes_off_by_path and eras.landed(state):
            requests = eras.take_off_by_path(found.method.module, requests)
        return [("execute_behavior" if r.wait else "activate_behavior", r.behavior, r.arguments,
                 {k for k, v in r.arguments.items() if unknown(v)}) for r in requests]

    def node_of(self, found: As2Call, argument: str) -> ast.AST:
        """Where in the call the catalog argument ``argument`` came from (the call itself if not told apart)."""
        return next((found.nodes[p] for p in _SOURCES.get(argument, ()) if p in found.nodes), found.call)


def _topic_of(func: ast.Attribute, call: ast.Call | None) -> str:
    """For a subscription of a topic the call names: whose the topic is (another program's, which a ROS 2 graph
    brings; none runs here)."""
    if func.attr != "create_subscription" or call is None or len(call.args) < 2 or \
            not isinstance(call.args[1], ast.Constant) or not isinstance(call.args[1].value, str):
        return ""
    return f" (a subscription to {call.args[1].value}, which another program publishes)"


def unknown(value: Any) -> bool:
    """True for a value (or one inside it) the check cannot know."""
    if isinstance(value, Unknown | aerostack2.Unplaced):
        return True
    return isinstance(value, tuple) and any(unknown(v) for v in value)


def _targets(node: ast.AST) -> list[ast.AST]:
    if isinstance(node, ast.Assign):
        return list(node.targets)
    if isinstance(node, ast.AnnAssign | ast.AugAssign):
        return [node.target]
    return []


__all__ = ["As2Call", "DroneClass", "DroneObjects", "Unknown", "unknown"]
