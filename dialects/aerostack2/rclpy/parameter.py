"""``rclpy.parameter`` as a mission sees it: :class:`Parameter` (a name, a type and a value), its ``Type``, and the
values ``--ros-args -p NAME:=VALUE`` gives (:func:`parse_value`: YAML, as rcl reads them)."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any

from aeroexec.lazy import lazy_module

yaml = lazy_module("yaml")



class _Type(enum.IntEnum):
    """A parameter's type, numbered as ``rcl_interfaces/msg/ParameterType``."""

    NOT_SET = 0
    BOOL = 1
    INTEGER = 2
    DOUBLE = 3
    STRING = 4
    BYTE_ARRAY = 5
    BOOL_ARRAY = 6
    INTEGER_ARRAY = 7
    DOUBLE_ARRAY = 8
    STRING_ARRAY = 9

    @classmethod
    def from_parameter_value(cls, value: Any) -> _Type:
        """The type of ``value`` (TypeError for a value no ROS 2 parameter can hold)."""
        if value is None:
            return cls.NOT_SET
        if isinstance(value, bool):
            return cls.BOOL
        if isinstance(value, int):
            return cls.INTEGER
        if isinstance(value, float):
            return cls.DOUBLE
        if isinstance(value, str):
            return cls.STRING
        if isinstance(value, bytes):
            return cls.BYTE_ARRAY
        if isinstance(value, list | tuple):
            for kind, array in ((bool, cls.BOOL_ARRAY), (int, cls.INTEGER_ARRAY), (float, cls.DOUBLE_ARRAY),
                                (str, cls.STRING_ARRAY), (bytes, cls.BYTE_ARRAY)):
                if all(isinstance(v, kind) and (kind is bool or not isinstance(v, bool)) for v in value):
                    return array
        raise TypeError(f"The given value is not one of the allowed types: {value!r}")

    def check(self, value: Any) -> bool:
        """True when ``value`` is of this type (an empty list is of every array type)."""
        if self is _Type.NOT_SET:
            return value is None
        try:
            found = _Type.from_parameter_value(value)
        except TypeError:
            return False
        return found is self or (isinstance(value, list | tuple) and not value and self.name.endswith("_ARRAY"))


@dataclass
class ParameterValue:
    """``rcl_interfaces/msg/ParameterValue``: the type and the field of that type set."""

    type: int = 0
    bool_value: bool = False
    integer_value: int = 0
    double_value: float = 0.0
    string_value: str = ""
    byte_array_value: list[bytes] = field(default_factory=list)
    bool_array_value: list[bool] = field(default_factory=list)
    integer_array_value: list[int] = field(default_factory=list)
    double_array_value: list[float] = field(default_factory=list)
    string_array_value: list[str] = field(default_factory=list)


class Parameter:
    """A parameter: ``Parameter(name, type_=None, value=None)``; without a type, the value's."""

    Type = _Type

    def __init__(self, name: str, type_: _Type | None = None, value: Any = None) -> None:
        if type_ is None:
            type_ = _Type.from_parameter_value(value)
        if not isinstance(type_, _Type):
            raise TypeError("type must be an instance of Parameter.Type")
        if not type_.check(value):
            raise ValueError(f"Type {type_} and value {value!r} do not agree")
        self._name, self._type, self._value = name, type_, value

    @property
    def name(self) -> str:
        return self._name

    @property
    def type_(self) -> _Type:
        return self._type

    @property
    def value(self) -> Any:
        return self._value

    def get_parameter_value(self) -> ParameterValue:
        found = ParameterValue(type=int(self._type))
        if self._type is not _Type.NOT_SET:
            setattr(found, f"{self._type.name.lower()}_value", list(self._value) if isinstance(self._value, tuple)
                    else self._value)
        return found

    def __repr__(self) -> str:
        return f"Parameter({self._name!r}, {self._type}, {self._value!r})"


def parse_value(text: str) -> Any:
    """A parameter's value as ``--ros-args -p NAME:=VALUE`` gives it: read as YAML, as rcl reads it (``2`` an
    integer, ``2.0`` a double, ``true`` a bool, ``[1, 2]`` an integer array, anything else a string)."""
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    if value is None and text.strip() not in ("", "~", "null", "Null", "NULL"):
        return text
    try:
        _Type.from_parameter_value(value)
    except TypeError:
        return text
    return value


__all__ = ["Parameter", "ParameterValue", "parse_value"]
