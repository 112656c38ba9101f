"""``rclpy.time`` and ``rclpy.duration`` as a mission sees them: :class:`Time` (nanoseconds on a clock) and
:class:`Duration`, with rclpy's arithmetic and comparisons."""

from __future__ import annotations

import enum
from typing import Any

from aeroexec.dialects.ros_messages import MESSAGES

S_TO_NS = 1_000_000_000


class ClockType(enum.IntEnum):
    """What a clock reads (``rclpy.clock.ClockType``)."""

    UNINITIALIZED = 0
    ROS_TIME = 1
    SYSTEM_TIME = 2
    STEADY_TIME = 3


class Duration:
    """A span of time: ``Duration(seconds=1.5)``, ``Duration(nanoseconds=...)``."""

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0) -> None:
        self._nanoseconds = int(seconds * S_TO_NS) + int(nanoseconds)

    @property
    def nanoseconds(self) -> int:
        return self._nanoseconds

    def to_msg(self) -> Any:
        sec, nanosec = divmod(self._nanoseconds, S_TO_NS)
        return MESSAGES["builtin_interfaces.msg"]["Duration"](sec=sec, nanosec=nanosec)

    @classmethod
    def from_msg(cls, msg: Any) -> Duration:
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Duration) and other._nanoseconds == self._nanoseconds

    def __lt__(self, other: Duration) -> bool:
        return self._nanoseconds < other._nanoseconds

    def __le__(self, other: Duration) -> bool:
        return self._nanoseconds <= other._nanoseconds

    def __gt__(self, other: Duration) -> bool:
        return self._nanoseconds > other._nanoseconds

    def __ge__(self, other: Duration) -> bool:
        return self._nanoseconds >= other._nanoseconds

    def __hash__(self) -> int:
        return hash(self._nanoseconds)

    def __repr__(self) -> str:
        return f"Duration(nanoseconds={self._nanoseconds})"


class Time:
    """A time on a clock: ``Time(seconds=..., nanoseconds=..., clock_type=...)``; ``seconds_nanoseconds()``,
    ``to_msg()``; a Time less a Time is a :class:`Duration`, a Time plus a Duration a Time."""

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0, clock_type: Any = None) -> None:
        total = int(seconds * S_TO_NS) + int(nanoseconds)
        if total < 0:
            raise ValueError("Total nanoseconds value is too low")
        self._nanoseconds, self._clock_type = total, clock_type or ClockType.SYSTEM_TIME

    @property
    def nanoseconds(self) -> int:
        return self._nanoseconds

    @property
    def clock_type(self) -> Any:
        return self._clock_type

    def seconds_nanoseconds(self) -> tuple[int, int]:
        return divmod(self._nanoseconds, S_TO_NS)

    def to_msg(self) -> Any:
        sec, nanosec = self.seconds_nanoseconds()
        return MESSAGES["builtin_interfaces.msg"]["Time"](sec=sec, nanosec=nanosec)

    @classmethod
    def from_msg(cls, msg: Any, clock_type: Any = None) -> Time:
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec, clock_type=clock_type)

    def __sub__(self, other: Any) -> Any:
        if isinstance(other, Time):
            if other._clock_type != self._clock_type:
                raise TypeError("Can't subtract times with different clock types")
            return Duration(nanoseconds=self._nanoseconds - other._nanoseconds)
        if isinstance(other, Duration):
            return Time(nanoseconds=self._nanoseconds - other.nanoseconds, clock_type=self._clock_type)
        return NotImplemented

    def __add__(self, other: Any) -> Time:
        if isinstance(other, Duration):
            return Time(nanoseconds=self._nanoseconds + other.nanoseconds, clock_type=self._clock_type)
        return NotImplemented

    __radd__ = __add__

    def _compare(self, other: Any) -> int:
        if not isinstance(other, Time):
            raise TypeError(f"Can't compare Time with {type(other).__name__}")
        if other._clock_type != self._clock_type:
            raise TypeError("Can't compare times with different clock types")
        return (self._nanoseconds > other._nanoseconds) - (self._nanoseconds < other._nanoseconds)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Time) and self._compare(other) == 0

    def __lt__(self, other: Time) -> bool:
        return self._compare(other) < 0

    def __le__(self, other: Time) -> bool:
        return self._compare(other) <= 0

    def __gt__(self, other: Time) -> bool:
        return self._compare(other) > 0

    def __ge__(self, other: Time) -> bool:
        return self._compare(other) >= 0

    def __hash__(self) -> int:
        return hash((self._nanoseconds, self._clock_type))

    def __repr__(self) -> str:
        return f"Time(nanoseconds={self._nanoseconds}, clock_type={self._clock_type.name})"


__all__ = ["S_TO_NS", "ClockType", "Duration", "Time"]
