"""The ROS 2 context of a mission's ``rclpy``: whether it is initialised (``rclpy.ok()``), and the ROS arguments
it was initialised with, read as rcl reads them.

ROS arguments come after ``--ros-args`` on a program's command line, up to a lone ``--`` or the next
``--ros-args``: ``-p``/``--param NAME:=VALUE`` (``NODE:NAME:=VALUE`` for one node), ``--params-file FILE``
(``NODE: {ros__parameters: {...}}``, ``/**`` for every node), ``-r``/``--remap FROM:=TO`` (``__ns``, ``__node``;
``NODE:FROM:=TO``), ``--log-level``, ``--enclave``. An argument rcl does not know is an error, as rcl refuses it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.dialects.aerostack2.rclpy.parameter import parse_value

from aeroexec.lazy import lazy_module

yaml = lazy_module("yaml")


class RosArgumentError(ValueError):
    """A ROS argument rcl would refuse (``rclpy.init`` fails with it)."""


@dataclass
class RosArguments:
    """What ``--ros-args`` says: parameters and remappings, each for every node (node None) or for one."""

    parameters: list[tuple[str | None, str, Any]] = field(default_factory=list)  # (node, name, value)
    remaps: list[tuple[str | None, str, str]] = field(default_factory=list)  # (node, from, to)

    def for_node(self, name: str, fully_qualified: str) -> dict[str, Any]:
        """The parameters given to the node ``name`` (``/ns/name`` fully qualified), the node's own last."""
        mine = (None, "/**", name, fully_qualified, fully_qualified.lstrip("/"))
        found = {param: value for node, param, value in self.parameters if node in (None, "/**")}
        found.update({param: value for node, param, value in self.parameters if node in mine[2:]})
        return found

    def remapped(self, key: str, name: str, default: str) -> str:
        """``__ns`` or ``__node`` as remapped for the node ``name`` (``default`` when it is not)."""
        found = default
        for node, source, target in self.remaps:
            if source == key and node in (None, name):
                found = target
        return found

    def extend(self, other: RosArguments) -> RosArguments:
        return RosArguments(self.parameters + other.parameters, self.remaps + other.remaps)


def ros_arguments(args: list[str] | tuple[str, ...]) -> RosArguments:
    """The ROS arguments of a command line (the program's own arguments around them are left alone)."""
    found = RosArguments()
    words, ros, i = [str(a) for a in args], False, 0
    while i < len(words):
        word = words[i]
        if word == "--ros-args":
            ros = True
        elif not ros:
            pass
        elif word == "--":
            ros = False
        elif word in ("-p", "--param", "-r", "--remap", "--params-file", "--log-level", "-e", "--enclave"):
            if i + 1 >= len(words):
                raise RosArgumentError(f"--ros-args: {word} needs a value after it")
            i += 1
            _one(found, word, words[i])
        elif word in ("--enable-rosout-logs", "--disable-rosout-logs", "--enable-stdout-logs",
                      "--disable-stdout-logs", "--enable-external-lib-logs", "--disable-external-lib-logs"):
            pass
        else:
            raise RosArgumentError(f"--ros-args: rcl does not know the argument {word!r} (use -p NAME:=VALUE for a "
                                   f"parameter, -r FROM:=TO for a remapping, --params-file FILE)")
        i += 1
    return found


def _one(found: RosArguments, flag: str, value: str) -> None:
    if flag in ("--log-level", "-e", "--enclave"):
        return
    if flag == "--params-file":
        found.parameters += params_file(value)
        return
    rule, sep, target = value.partition(":=")
    if not sep or not rule:
        raise RosArgumentError(f"--ros-args {flag} {value}: give NAME:=VALUE")
    node, colon, name = rule.rpartition(":")
    if flag in ("-p", "--param"):
        found.parameters.append((node if colon else None, name, parse_value(target)))
    else:
        found.remaps.append((node if colon else None, name, target))


def params_file(path: str) -> list[tuple[str | None, str, Any]]:
    """The parameters of a ROS 2 parameters file (``NODE: {ros__parameters: {...}}``), nested names joined by dots."""
    try:
        document = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as error:
        raise RosArgumentError(f"--params-file {path}: {error}") from None
    if not isinstance(document, dict):
        raise RosArgumentError(f"--params-file {path}: not a map of nodes to their ros__parameters")
    found: list[tuple[str | None, str, Any]] = []
    for node, body in document.items():
        values = body.get("ros__parameters") if isinstance(body, dict) else None
        if not isinstance(values, dict):
            raise RosArgumentError(f"--params-file {path}: {node} has no ros__parameters")
        found += [(str(node), name, value) for name, value in _flat(values)]
    return found


def _flat(values: dict[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    found: list[tuple[str, Any]] = []
    for key, value in values.items():
        if isinstance(value, dict):
            found += _flat(value, f"{prefix}{key}.")
        else:
            found.append((f"{prefix}{key}", value))
    return found


class Context:
    """A ROS 2 context: initialised by ``rclpy.init``, shut down by ``rclpy.shutdown`` (from a timer's callback
    too: the spin running it then returns)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._ok = False
        self.arguments = RosArguments()
        self._on_shutdown: list[Any] = []

    def init(self, args: list[str] | tuple[str, ...]) -> None:
        arguments = ros_arguments(args)
        with self._lock:
            self.arguments, self._ok = arguments, True

    def ok(self) -> bool:
        return self._ok

    def shutdown(self) -> None:
        with self._lock:
            self._ok = False
            callbacks, self._on_shutdown = self._on_shutdown, []
        for callback in callbacks:
            callback()

    def on_shutdown(self, callback: Any) -> None:
        with self._lock:
            self._on_shutdown.append(callback)


#: The context of every node and executor not given another (rclpy's default context).
DEFAULT = Context()

__all__ = ["DEFAULT", "Context", "RosArgumentError", "RosArguments", "params_file", "ros_arguments"]
