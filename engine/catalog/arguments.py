"""Behavior arguments: what values an argument allows (range, enumeration, type, a place in the world) and checking a
value against it.

A point argument whose catalog entry says ``allowed_values: WORLD`` is a place to fly to: local ENU meters
``(x, y, z)`` or a geographic point ``geo:LAT,LON,ALT`` (:mod:`aeroexec.drones.geodesy`). Against a world it must
be inside the world's bounds and geofence (:mod:`.world_check`); without one, within the vehicle's documented
reach (``vehicle_limits``: ``max_distance`` from home horizontally, ``max_altitude`` up or down).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass

from aeroexec.beliefs import BeliefError, parse_expression
from aeroexec.drones.geodesy import is_geo, parse_geo

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: Value types a catalog may name in ``allowed_values`` or ``type``.
VALUE_TYPES = {
    "TEXT": "a text",
    "IMAGE": "an image name",
    "NUMBER": "a number",
    "INTEGER": "an integer",
    "BOOLEAN": "true or false",
    "POINT": "a point (x, y, z)",
    "PATH": "a list of points (x, y, z)",
    "TEXT_LIST": "a list of texts",
    "BELIEF": "a belief expression",
}


def _is_number(value: Any) -> bool:
    """A finite int or float; an integer beyond a float's range (a 400-digit literal) is not a number here."""
    if not isinstance(value, int | float) or isinstance(value, bool):
        return False
    return abs(value) <= sys.float_info.max if isinstance(value, int) else math.isfinite(value)


def _fmt(number: float) -> str:
    return f"{number:g}"


@dataclass(frozen=True, slots=True)
class ArgumentDescriptor:
    """One argument of a behavior as the catalog describes it.

    ``minimum``/``maximum`` give a numeric range, ``choices`` an enumeration,
    ``value_type`` one of :data:`VALUE_TYPES`; ``dimensions`` is how many numbers
    a value has (a point has 3). With none of them any value is accepted.
    """

    name: str
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple[str, ...] = ()
    value_type: str | None = None
    dimensions: int = 1
    required: bool = False
    default: Any = None
    description: str = ""
    aliases: tuple[str, ...] = ()  # other names a request may use (the paper's Table 8 writes point=)
    line: int = 0
    #: ``allowed_values: WORLD``: a place in the world (see the module's docstring); ``reach`` is the vehicle's
    #: (horizontal, vertical) meters from home a point may be without a world
    in_world: bool = False
    reach: tuple[float, float] | None = None

    @property
    def is_range(self) -> bool:
        return self.minimum is not None

    @property
    def is_place(self) -> bool:
        """Whether its values are places (points or paths of points) that may be written ``geo:LAT,LON,ALT``."""
        return self.in_world

    def _reach_text(self) -> str:
        if self.reach is None:
            return ""
        return f" (x and y within {_fmt(self.reach[0])} m of home, z within {_fmt(self.reach[1])} m)"

    def expected(self) -> str:
        """What a correct value looks like, for the paper's "(... is expected)"."""
        within = f" between {_fmt(self.minimum)} and {_fmt(self.maximum)}" if self.is_range else ""
        if self.choices:
            return "one of " + ", ".join(self.choices)
        if self.in_world and self.value_type == "PATH":
            return f"a list of points (x, y, z) or geo:LAT,LON,ALT in the world{self._reach_text()}"
        if self.in_world:
            return f"a point (x, y, z) or geo:LAT,LON,ALT in the world{self._reach_text()}"
        if self.value_type == "PATH":
            return "a list of points (x, y, z)" + (f" with coordinates{within}" if within else "")
        if self.value_type == "POINT" or (self.dimensions == 3 and self.value_type is None and self.is_range):
            return f"a point (x, y, z){' with coordinates' + within if within else ''}"
        if self.dimensions > 1:
            return f"{self.dimensions} numbers{within}"
        if self.value_type is not None:
            return VALUE_TYPES[self.value_type] + within
        return f"a number{within}" if within else "any value"

    def describe(self) -> str:
        """The allowed values as the catalog listing shows them."""
        if self.choices:
            return "{" + ", ".join(self.choices) + "}"
        text = self.value_type or ""
        if self.in_world:
            reach = f" (<= {_fmt(self.reach[0])} m from home, |z| <= {_fmt(self.reach[1])} m)" if self.reach else ""
            return f"{text or 'POINT'} in the world{reach}"
        if self.is_range:
            text = f"{text} [{_fmt(self.minimum)}, {_fmt(self.maximum)}]".strip()
        if self.dimensions > 1 and self.value_type not in ("POINT", "PATH"):
            text += f" x{self.dimensions}"
        return text or "any"

    def accepts(self, value: Any) -> bool:
        """True when ``value`` is allowed for this argument."""
        if self.choices:
            return isinstance(value, str) and value in self.choices
        kind = self.value_type
        if kind in ("TEXT", "IMAGE"):
            return isinstance(value, str)
        if kind == "BOOLEAN":
            return isinstance(value, bool)
        if kind == "BELIEF":
            return isinstance(value, str) and _is_belief(value)
        if kind == "TEXT_LIST":
            return _is_sequence(value) and all(isinstance(v, str) for v in value)
        if self.in_world:
            if kind == "PATH":
                return _is_sequence(value) and len(value) > 0 and all(self._place(p) for p in value)
            return self._place(value)
        if kind == "PATH":
            return _is_sequence(value) and len(value) > 0 and all(self._numbers(p, 3) for p in value)
        if kind == "POINT":
            return self._numbers(value, 3)
        if kind == "INTEGER" and not (isinstance(value, int) and not isinstance(value, bool)):
            return False
        if kind == "NUMBER" or kind == "INTEGER" or self.is_range or self.dimensions > 1:
            return self._numbers(value, self.dimensions)
        return True

    def _numbers(self, value: Any, dimensions: int) -> bool:
        if dimensions == 1 and not _is_sequence(value):
            items: Sequence = (value,)
        elif _is_sequence(value) and len(value) == dimensions:
            items = value
        else:
            return False
        return all(_is_number(v) and self._in_range(v) for v in items)

    def _in_range(self, number: float) -> bool:
        return not self.is_range or self.minimum <= number <= self.maximum

    def _place(self, value: Any) -> bool:
        """A point in the vehicle's reach: three numbers, or a well formed ``geo:`` point."""
        if is_geo(value):
            try:
                height = parse_geo(value)[2]
            except ValueError:
                return False
            return self.reach is None or abs(height) <= self.reach[1]
        if not (_is_sequence(value) and len(value) == 3 and all(_is_number(v) for v in value)):
            return False
        if self.reach is None:
            return True
        return math.hypot(value[0], value[1]) <= self.reach[0] and abs(value[2]) <= self.reach[1]


def _is_sequence(value: Any) -> bool:
    return isinstance(value, list | tuple)


def _is_belief(text: str) -> bool:
    try:
        parse_expression(text)
    except BeliefError:
        return False
    return True


def format_value(value: Any) -> str:
    """A value as the operator wrote it, for error messages."""
    if isinstance(value, str):
        return value if value else "''"
    if isinstance(value, bool):
        return "true" if value else "false"
    if _is_sequence(value):
        return "(" + ", ".join(format_value(v) for v in value) + ")"
    if value is None:
        return "(none)"
    return str(value)
