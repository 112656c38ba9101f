"""Values as BehaviorTree.CPP converts them: text to a port's type (its ``convertFromString<T>``), blackboard values
read by typed ports (its ``Any::cast<T>``: numbers cast when nothing is lost), and values back to text (``toStr``).

Port types are named as BT.CPP's C++ types: ``int``, ``unsigned``, ``double``, ``bool``, ``string``,
``NodeStatus``; ``any`` takes a value as it is. Integers and doubles are read as ``std::from_chars`` reads them:
the number at the start of the text, what follows ignored (``"3.5"`` is the integer 3), no leading space or ``+``.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable

from aeroexec.limits import MAX_NUMBER_LENGTH

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: Port types (BT.CPP's C++ types).
INT, UNSIGNED, DOUBLE, BOOL, STRING, STATUS, ANY = "int", "unsigned", "double", "bool", "string", "NodeStatus", "any"
#: BT.CPP's fourth status (py_trees has three and INVALID, BT.CPP's IDLE).
SKIPPED = "SKIPPED"


class ConversionError(ValueError):
    """A value that cannot be converted to the type asked (BT.CPP's message)."""


_INTEGER = re.compile(r"-?\d+")  # std::from_chars: an optional '-', digits; what follows is not read
_DOUBLE = re.compile(r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|-?(?:infinity|inf|nan)", re.IGNORECASE)
_BOUNDS = {INT: (-(2 ** 31), 2 ** 31 - 1), UNSIGNED: (0, 2 ** 32 - 1)}  # C++ int and unsigned


def integer_prefix(text: str) -> int | None:
    """The integer BT.CPP reads at the start of ``text`` (``"3.5"`` and ``"3abc"`` read 3), None when none."""
    match = _INTEGER.match(text[:MAX_NUMBER_LENGTH + 1])
    return int(match.group()) if match is not None and len(match.group()) <= MAX_NUMBER_LENGTH else None


def _bounded(value: int, kind: str, text: str) -> int:
    low, high = _BOUNDS[kind]
    if not low <= value <= high:
        raise ConversionError(f"Value out of bound when converting [{text}] to integer")
    return value


def _integer(text: str, kind: str = INT) -> int:
    value = integer_prefix(text)
    if value is None:
        raise ConversionError(f"Can't convert string [{text}] to integer")
    return _bounded(value, kind, text)


def _double(text: str) -> float:
    match = _DOUBLE.match(text[:MAX_NUMBER_LENGTH + 1])
    if match is None or len(match.group()) > MAX_NUMBER_LENGTH:
        raise ConversionError(f"Can't convert string [{text}] to double")
    return float(match.group())


def _bool(text: str) -> bool:
    if text in ("1", "true", "TRUE", "True"):
        return True
    if text in ("0", "false", "FALSE", "False"):
        return False
    raise ConversionError("convertFromString(): invalid bool conversion")


@functools.cache
def _node_statuses() -> tuple[type, dict[str, Any], dict[int, Any]]:
    """py_trees' ``Status``, NodeStatus by its text and by BT.CPP's numbers. py_trees is imported here, when a status
    is first converted: verification converts every other type without loading it."""
    from py_trees.common import Status

    by_text = {"SUCCESS": Status.SUCCESS, "FAILURE": Status.FAILURE, "RUNNING": Status.RUNNING, "SKIPPED": SKIPPED,
               "IDLE": Status.INVALID}
    by_code = {0: Status.INVALID, 1: Status.RUNNING, 2: Status.SUCCESS, 3: Status.FAILURE, 4: SKIPPED}
    return Status, by_text, by_code


def _status(text: str) -> Any:
    _, by_text, _ = _node_statuses()
    if text not in by_text:
        raise ConversionError(f"Cannot convert this to NodeStatus: {text}")
    return by_text[text]


#: BT.CPP's ``convertFromString<T>``, per port type (text as written: BT.CPP strips nothing).
CONVERSIONS: dict[str, Callable[[str], Any]] = {INT: _integer, UNSIGNED: lambda text: _integer(text, UNSIGNED),
                                                DOUBLE: _double, BOOL: _bool, STATUS: _status, STRING: str, ANY: str}


def compatible(known: str | None, kind: str) -> bool:
    """Whether a port of type ``kind`` may use an entry a port of type ``known`` made first (BT.CPP: the same type,
    any type after a string's, and anything when either is untyped)."""
    return known is None or known in (kind, STRING, ANY) or kind == ANY


def type_conflict(key: str, known: str, kind: str) -> str:
    """BT.CPP's message refusing a tree whose ports give one entry two types."""
    return (f"The creation of the tree failed because the port [{key}] was initially created with type [{known}] "
            f"and, later type [{kind}] was used somewhere else.")


def queue_items(text: str, item: str) -> list[Any]:
    """BT.CPP's ``convertFromString<SharedQueue<T>>``: the items between ``;``, each converted (none in "")."""
    parts = text.split(";")
    if parts and not parts[-1]:
        parts.pop()  # "1;2;" has two items, as in BT.CPP's splitString
    return [convert(part, item) for part in parts]


def convert(text: str, kind: str) -> Any:
    """A port's text as a value of type ``kind`` (raises :class:`ConversionError`)."""
    return CONVERSIONS[kind](text)


def text_of(value: Any) -> str:
    """A value as BT.CPP writes it as text (``std::to_string``: a double with six decimals; a bool as 1 or 0)."""
    if isinstance(value, bool):
        return str(int(value))
    return f"{value:.6f}" if isinstance(value, float) else str(value)


def from_blackboard(value: Any, kind: str) -> Any:
    """A blackboard value read by a port of type ``kind``, as BT.CPP's ``getInput<T>`` reads an entry: text is
    converted from string, numbers are cast when nothing is lost (raises :class:`ConversionError`)."""
    if kind == ANY:
        return value
    if isinstance(value, str):
        return convert(value, kind)
    number = isinstance(value, int | float)
    if kind == STRING and number:
        return text_of(value)
    if kind in (STRING, STATUS):
        status, _, by_code = _node_statuses()
        if isinstance(value, status):
            return value.value if kind == STRING else value
        if kind == STATUS and isinstance(value, int) and value in by_code:
            return by_code[value]
    if kind in (INT, UNSIGNED) and number:
        if isinstance(value, float) and (not math.isfinite(value) or value != int(value)):
            raise ConversionError("Invalid floating point to integer conversion")
        if kind == UNSIGNED and value < 0:
            raise ConversionError("Value is negative and can't be converted to unsigned")
        return _bounded(int(value), kind, text_of(value))
    if kind == DOUBLE and number:
        return float(value)
    if kind == BOOL and number:
        return bool(value)
    raise ConversionError(f"no known safe conversion between [{type(value).__name__}] and [{kind}]")
