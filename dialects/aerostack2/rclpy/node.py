"""``rclpy.node.Node`` as a mission sees it: a script's own node (Aerostack2's scripts subclass it or make one),
served as far as it needs no ROS 2 graph.

Served: ``get_logger()``, ``get_name()``, ``get_namespace()``, ``get_fully_qualified_name()``; parameters
(``declare_parameter(s)``, ``get_parameter(s)``, ``get_parameter_or``, ``has_parameter``, ``set_parameters``,
``undeclare_parameter``, ``add_on_set_parameters_callback``), each one's value its declared default or what
``--ros-args -p NAME:=VALUE`` in the script's arguments gives it (``aeroexec run script.py -- --ros-args -p ...``),
statically typed as in ROS 2; ``get_clock()`` (the engine's clock); timers (``create_timer(period_sec, callback)``,
``destroy_timer``), whose callbacks the executor spinning the node runs on the engine's clock; publishers of
messages used as data (``create_publisher``: the event log); ``destroy_node()``.

Refused, naming the method: whatever needs a ROS 2 graph (subscriptions, services, clients, the graph's queries):
this mission uses ROS 2 beyond the drone interface. ``aeroexec verify`` says so before flight, at the line
(:mod:`aeroexec.dialects.aerostack2.ros_nodes`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from aeroexec.dialects import ros
from aeroexec.dialects.aerostack2.node_api import NODE_API
from aeroexec.dialects.aerostack2.rclpy import context as contexts
from aeroexec.dialects.aerostack2.rclpy.clock import ROSClock
from aeroexec.dialects.aerostack2.rclpy.exceptions import (
    InvalidParameterTypeException,
    ParameterAlreadyDeclaredException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from aeroexec.dialects.aerostack2.rclpy.logging import RcutilsLogger
from aeroexec.dialects.aerostack2.rclpy.parameter import Parameter
from aeroexec.dialects.aerostack2.rclpy.publisher import Publisher, publisher, resolve_topic
from aeroexec.dialects.aerostack2.rclpy.time import S_TO_NS
from aeroexec.dialects.aerostack2.rclpy.timer import Timer
from aeroexec.engine import api


@dataclass
class SetParametersResult:
    """``rcl_interfaces/msg/SetParametersResult``."""

    successful: bool = True
    reason: str = ""


class Node:
    """A ROS 2 node of the script's own: ``Node(node_name, *, namespace=None, cli_args=None,
    parameter_overrides=None, allow_undeclared_parameters=False,
    automatically_declare_parameters_from_overrides=False, ...)``."""

    def __init__(self, node_name: str, *, context: Any = None, cli_args: list[str] | None = None,
                 namespace: str | None = None, use_global_arguments: bool = True, enable_rosout: bool = True,
                 start_parameter_services: bool = True, parameter_overrides: list[Parameter] | None = None,
                 allow_undeclared_parameters: bool = False,
                 automatically_declare_parameters_from_overrides: bool = False, **_: Any) -> None:
        self._context = context or contexts.DEFAULT
        arguments = self._context.arguments if use_global_arguments else contexts.RosArguments()
        if cli_args:
            arguments = arguments.extend(contexts.ros_arguments(cli_args))
        self._name = arguments.remapped("__node", node_name, node_name)
        namespace = arguments.remapped("__ns", self._name, namespace or "/")
        self._namespace = "/" + namespace.strip("/")
        self._logger = RcutilsLogger(self._name)
        self._clock = ROSClock()
        self._overrides: dict[str, Parameter] = {
            name: Parameter(name, value=value)
            for name, value in arguments.for_node(self._name, self.get_fully_qualified_name()).items()}
        self._overrides.update({p.name: p for p in parameter_overrides or ()})
        self._parameters: dict[str, Parameter] = {}
        self._types: dict[str, Parameter.Type] = {}  # each parameter's declared type (statically typed)
        self._allow_undeclared = allow_undeclared_parameters
        self._on_set: list[Callable[[list[Parameter]], Any]] = []
        self.timers: list[Timer] = []
        self.publishers: list[Publisher] = []
        self.executor: Any = None
        self.declare_parameter("use_sim_time", False)
        if automatically_declare_parameters_from_overrides:
            for name, override in self._overrides.items():
                if name not in self._parameters:
                    self._parameters[name] = override

    # -- ROS 2's graph, which aeroexec has not ----------------------------------------------------------------
    def __getattr__(self, name: str) -> Any:
        if name.startswith(NODE_API) or name in ("handle", "subscriptions", "clients", "services",
                                                 "guards", "waitables"):
            return ros.Refused(f"{type(self).__name__}.{name}")
        raise AttributeError(f"'{type(self).__name__}' object has no attribute '{name}'")

    # -- the node -----------------------------------------------------------------------------------------------
    @property
    def context(self) -> Any:
        return self._context

    @property
    def default_callback_group(self) -> None:
        return None

    def get_name(self) -> str:
        return self._name

    def get_namespace(self) -> str:
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        return f"{self._namespace.rstrip('/')}/{self._name}"

    def get_logger(self) -> RcutilsLogger:
        return self._logger

    def get_clock(self) -> ROSClock:
        return self._clock

    def destroy_node(self) -> bool:
        for timer in list(self.timers):
            timer.destroy()
        self.publishers.clear()
        if self.executor is not None:
            self.executor.remove_node(self)
        return True

    # -- timers -------------------------------------------------------------------------------------------------
    def create_timer(self, timer_period_sec: float, callback: Callable[[], Any] | None, callback_group: Any = None,
                     clock: Any = None, autostart: bool = True) -> Timer:
        """A timer calling ``callback`` every ``timer_period_sec`` seconds of the engine's clock while the node is
        spun (``rclpy.spin(node)``, an executor's ``spin``)."""
        timer = Timer(callback, int(float(timer_period_sec) * S_TO_NS), clock or self._clock, autostart, self)
        self.timers.append(timer)
        return timer

    def destroy_timer(self, timer: Timer) -> bool:
        if timer not in self.timers:
            return False
        timer.destroy()
        return True

    # -- publishers ---------------------------------------------------------------------------------------------
    def create_publisher(self, msg_type: Any, topic: str, qos_profile: Any = 10, **_: Any) -> Publisher:
        found = publisher(type(self).__name__, msg_type,
                          resolve_topic(str(topic), self._namespace, self._name), api.current_engine)
        self.publishers.append(found)
        return found

    def destroy_publisher(self, publisher: Publisher) -> bool:
        if publisher in self.publishers:
            self.publishers.remove(publisher)
        return publisher.destroy()

    # -- parameters -----------------------------------------------------------------------------------------------
    def declare_parameter(self, name: str, value: Any = None, descriptor: Any = None,
                          ignore_override: bool = False) -> Parameter:
        """Declare ``name`` with the default ``value`` (or a ``Parameter.Type``: typed, no value yet); its value is
        the override ``--ros-args -p NAME:=VALUE`` gives, when one does, of the default's type."""
        return self.declare_parameters("", [(name, value, descriptor)], ignore_override)[0]

    def declare_parameters(self, namespace: str, parameters: Iterable[Any],
                           ignore_override: bool = False) -> list[Parameter]:
        declared = []
        for entry in parameters:
            entry = (entry,) if isinstance(entry, str) else tuple(entry)
            name = f"{namespace}.{entry[0]}" if namespace else entry[0]
            value = entry[1] if len(entry) > 1 else None
            dynamic = bool(getattr(entry[2], "dynamic_typing", False)) if len(entry) > 2 else False
            if name in self._parameters:
                raise ParameterAlreadyDeclaredException([name])
            kind = value if isinstance(value, Parameter.Type) else None
            parameter = Parameter(name, Parameter.Type.NOT_SET if kind is not None else None,
                                  None if kind is not None else value)
            expected = kind or parameter.type_
            override = self._overrides.get(name)
            if override is not None and not ignore_override:
                if expected is not Parameter.Type.NOT_SET and not dynamic and override.type_ is not expected:
                    raise InvalidParameterTypeException(override, expected)
                parameter = Parameter(name, override.type_, override.value)
            self._parameters[name] = parameter
            if not dynamic:
                self._types[name] = expected
            declared.append(parameter)
        return declared

    def undeclare_parameter(self, name: str) -> None:
        if name not in self._parameters:
            raise ParameterNotDeclaredException(name)
        del self._parameters[name]
        self._types.pop(name, None)

    def has_parameter(self, name: str) -> bool:
        return name in self._parameters

    def get_parameter(self, name: str) -> Parameter:
        if name in self._parameters:
            found = self._parameters[name]
            if found.value is None and self._types.get(name, Parameter.Type.NOT_SET) is not Parameter.Type.NOT_SET:
                raise ParameterUninitializedException(name)
            return found
        if self._allow_undeclared:
            return Parameter(name, Parameter.Type.NOT_SET, None)
        raise ParameterNotDeclaredException(name)

    def get_parameters(self, names: Iterable[str]) -> list[Parameter]:
        return [self.get_parameter(name) for name in names]

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        if name in self._parameters:
            return self._parameters[name]
        return alternative_value if alternative_value is not None else Parameter(name, Parameter.Type.NOT_SET)

    def add_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        self._on_set.insert(0, callback)

    def remove_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        self._on_set.remove(callback)

    def set_parameters(self, parameter_list: list[Parameter]) -> list[SetParametersResult]:
        """Set each parameter (a declared one, of its type), as ROS 2 does: one result each."""
        results = []
        for parameter in parameter_list:
            if parameter.name not in self._parameters and not self._allow_undeclared:
                raise ParameterNotDeclaredException([parameter.name])
            results.append(self._set(parameter))
        return results

    def _set(self, parameter: Parameter) -> SetParametersResult:
        expected = self._types.get(parameter.name, Parameter.Type.NOT_SET)
        if expected is not Parameter.Type.NOT_SET and parameter.type_ is not expected:
            return SetParametersResult(False, f"Wrong parameter type, expected '{expected}' got "
                                              f"'{parameter.type_}'")
        for callback in self._on_set:
            result = callback([parameter])
            if not getattr(result, "successful", True):
                return SetParametersResult(False, getattr(result, "reason", ""))
        self._parameters[parameter.name] = parameter
        return SetParametersResult(True)


__all__ = ["Node", "SetParametersResult"]
