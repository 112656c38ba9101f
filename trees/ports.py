"""Port text to typed argument values (numbers, points, paths, enumerations, booleans, text); ``{key}`` read late.

Ports hold text as the operator wrote it (``"1, 2, 1.5"``, ``"1;2;1.5"``, ``"[1, 2, 1.5]"``, ``"{P}"``, a geographic
point ``"geo:47.3977,8.5456,10"``; a path of them separated by ``;``). A value
that cannot be read as the catalog's argument expects stays the text it was, so the specialist reports it in the
paper's words (Table 1: "The value x of argument y for behavior z is not correct (... is expected)").
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping

from aeroexec.beliefs import format_term
from aeroexec.beliefs.terms import from_python
from aeroexec.drones.geodesy import is_geo
from aeroexec.engine.catalog import BehaviorSpecialist
from aeroexec.engine.catalog.arguments import ArgumentDescriptor
from aeroexec.engine.catalog.descriptors import BehaviorDescriptor
from aeroexec.engine.errors import WRONG_VALUE, SpecificationError
from aeroexec.trees.model import COMMON_ATTRIBUTES

from aeroexec.limits import MAX_NUMBER_LENGTH

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

_KEY = re.compile(r"\{([^{}]+)\}")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
_TRUE, _FALSE = ("true", "yes", "on", "1"), ("false", "no", "off", "0")
#: Ports a behavior leaf reads besides the behavior's arguments: seconds overriding the catalog's timeout.
OPTIONS = ("timeout",)


class MissingKey(KeyError):
    """A port reads a blackboard key that no node has written."""

    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key

    def __str__(self) -> str:
        return f"the blackboard has no value for {{{self.key}}}"


def bare_key(text: str) -> str | None:
    """The blackboard key of a port written ``{key}``, else None."""
    text = text.strip()
    if len(text) > 2 and text[0] == "{" and text[-1] == "}" and "{" not in text[1:-1] and "}" not in text[1:-1]:
        return text[1:-1].strip()
    return None


def output_key(text: str) -> str:
    """The key an output port writes: ``{key}`` or a plain ``key``."""
    return bare_key(text) or text.strip()


def template_keys(text: str) -> list[str]:
    """Every blackboard key a port text reads (``{key}`` anywhere in it)."""
    return [m.group(1).strip() for m in _KEY.finditer(text or "")]


def substitute(text: str, blackboard: Mapping[str, Any], as_term: bool = False) -> str:
    """``text`` with each ``{key}`` replaced by its blackboard value (as a belief term when ``as_term``)."""
    def value(match: re.Match) -> str:
        key = match.group(1).strip()
        if key not in blackboard:
            raise MissingKey(key)
        found = blackboard[key]
        if as_term:
            return format_term(from_python(found))
        return found if isinstance(found, str) else format_term(from_python(found))

    return _KEY.sub(value, text)


def parse_number(text: str) -> int | float | None:
    """The number ``text`` writes; None when it is no number, longer than ``MAX_NUMBER_LENGTH`` or beyond a float."""
    text = text.strip()
    if len(text) > MAX_NUMBER_LENGTH or not _NUMBER.fullmatch(text):
        return None
    number = float(text)
    if not math.isfinite(number):
        return None
    return int(text) if re.fullmatch(r"[+-]?\d+", text) else number


def parse_value(text: str) -> Any:
    """A number, a tuple (``[1, 2]``, ``(1, 2)``, ``1, 2``, ``1;2``; nested brackets, ``;`` between points) or text."""
    text = text.strip()
    if is_geo(text) and ";" not in text:  # a geographic point, geo:LAT,LON,ALT: one value
        return text
    if text[:1] in "[(" and text[-1:] in "])":
        parsed = _parse_brackets(text)
        if parsed is not None:
            return parsed
    if ";" in text:
        return tuple(parse_value(part) for part in text.split(";") if part.strip())
    if "," in text:
        return tuple(_scalar(part) for part in text.split(","))
    return _scalar(text)


def _scalar(text: str) -> Any:
    number = parse_number(text)
    return number if number is not None else text.strip()


def _parse_brackets(text: str) -> tuple | None:
    """Nested ``[...]``/``(...)`` lists of numbers and words; None when the brackets do not balance."""
    stack: list[list] = [[]]
    token = ""
    for char in text:
        if char in "[(":
            stack.append([])
        elif char in "])":
            if token.strip():
                stack[-1].append(_scalar(token))
            token = ""
            if len(stack) < 2:
                return None
            done = tuple(stack.pop())
            stack[-1].append(done)
        elif char in ",;":
            if token.strip():
                stack[-1].append(_scalar(token))
            token = ""
        else:
            token += char
    if len(stack) != 1 or token.strip() or len(stack[0]) != 1:
        return None
    return stack[0][0]


def convert(text: str, argument: ArgumentDescriptor | None) -> Any:
    """A port's text as the value ``argument`` expects; the text itself when it cannot be read that way."""
    if argument is None:
        return parse_value(text)
    raw = text.strip()
    if argument.choices:
        return next((c for c in argument.choices if str(c).lower() == raw.lower()), text)
    kind = argument.value_type
    if kind in ("TEXT", "IMAGE", "BELIEF"):
        return text
    if kind == "BOOLEAN":
        return True if raw.lower() in _TRUE else False if raw.lower() in _FALSE else text
    if kind == "TEXT_LIST":
        inner = raw[1:-1] if raw[:1] in "[(" and raw[-1:] in "])" else raw
        return tuple(part.strip() for part in re.split(r"[,;]", inner) if part.strip())
    value = parse_value(raw)
    if kind == "PATH":  # points, or geographic points separated by ";"
        return value if isinstance(value, tuple) and all(isinstance(p, tuple) or is_geo(p) for p in value) else text
    if kind == "POINT" or argument.dimensions > 1:
        return value if isinstance(value, tuple) and not any(isinstance(v, tuple) for v in value) else text
    if kind in ("NUMBER", "INTEGER") or argument.is_range:
        return value if isinstance(value, int | float) else text
    return value


def from_blackboard(value: Any, argument: ArgumentDescriptor | None) -> Any:
    """A blackboard value as an argument: text is read like a port, lists become tuples."""
    if isinstance(value, str):
        return convert(value, argument)
    if isinstance(value, list | tuple):
        return tuple(from_blackboard(v, None) if isinstance(v, list | tuple) else v for v in value)
    return value


def argument_names(descriptor: BehaviorDescriptor) -> dict[str, str]:
    """Port name (any case, aliases included) -> the catalog's argument name."""
    names: dict[str, str] = {}
    for argument in descriptor.arguments.values():
        for alias in (argument.name, *argument.aliases):
            names[alias.upper()] = argument.name
    return names


def request_from_ports(descriptor: BehaviorDescriptor, ports: Mapping[str, str],
                       blackboard: Mapping[str, Any] | None = None,
                       skip: tuple[str, ...] = ()) -> tuple[dict[str, Any], dict[str, Any]]:
    """The behavior's arguments and options (``timeout``) from a leaf's ports, ``{key}`` read from ``blackboard``.

    With no blackboard, a port that reads one keeps its text. Raises :class:`MissingKey`.
    """
    names = argument_names(descriptor)
    arguments: dict[str, Any] = {}
    options: dict[str, Any] = {}
    for port, text in ports.items():
        if port in COMMON_ATTRIBUTES or port in skip:
            continue
        if port in OPTIONS and port.upper() not in names:
            options[port] = parse_number(substitute(text, blackboard) if blackboard is not None else text)
            continue
        name = names.get(port.upper(), port.upper())
        argument = descriptor.arguments.get(name)
        key = bare_key(text)
        if blackboard is None:
            arguments[name] = text if key is not None or template_keys(text) else convert(text, argument)
        elif key is not None:
            if key not in blackboard:
                raise MissingKey(key)
            arguments[name] = from_blackboard(blackboard[key], argument)
        else:
            arguments[name] = convert(substitute(text, blackboard), argument)
    return arguments, options


def witness(argument: ArgumentDescriptor) -> Any:
    """Some value the argument accepts, standing for a value only known in flight (read from the blackboard)."""
    if argument.choices:
        return argument.choices[0]
    low = argument.minimum if argument.is_range else 0
    kind = argument.value_type
    candidates = {"TEXT": "x", "IMAGE": "x", "BELIEF": "p(x)", "BOOLEAN": True, "TEXT_LIST": ("x",),
                  "PATH": ((low, low, low),), "POINT": (low, low, low), "INTEGER": int(low)}
    if kind in candidates:
        return candidates[kind]
    return low if argument.dimensions == 1 else (low,) * argument.dimensions


def port_errors(specialist: BehaviorSpecialist, behavior: str, ports: Mapping[str, str],
                skip: tuple[str, ...] = ()) -> list[SpecificationError]:
    """The WRONG_FORMAT and WRONG_VALUE errors of a behavior leaf's ports; values read from the blackboard pass."""
    descriptor = specialist.catalog.behavior(behavior)
    if descriptor is None:
        return specialist.request_errors(behavior, {})
    arguments, options = request_from_ports(descriptor, ports, None, skip)
    deferred = {name for name, value in arguments.items()
                if isinstance(value, str) and template_keys(value)}
    checked = {name: (witness(descriptor.arguments[name]) if name in deferred and name in descriptor.arguments
                      else value) for name, value in arguments.items()}
    errors = [e for e in specialist.request_errors(behavior, checked)  # a witness is no place in the world
              if not any(f"argument {name} for " in e.message for name in deferred)]
    timeout = options.get("timeout")
    if "timeout" in options and (timeout is None or timeout <= 0) and not template_keys(ports.get("timeout", "")):
        errors.append(SpecificationError(WRONG_VALUE, f"The value {ports['timeout']} of argument timeout for behavior "
                                                      f"{behavior} is not correct (a positive number of seconds "
                                                      f"is expected)", behavior=behavior))
    return errors
