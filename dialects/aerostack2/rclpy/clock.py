"""``rclpy.clock`` as a mission sees it: every clock reads the engine's (simulated) clock, in nanoseconds from the
run's start, as a ROS 2 node with ``use_sim_time`` reads a simulator's ``/clock`` (Gazebo's starts at 0)."""

from __future__ import annotations

from aeroexec.dialects.aerostack2.rclpy.time import S_TO_NS, ClockType, Duration, Time
from aeroexec.engine import api


def now_ns() -> int:
    """The engine's clock now, in nanoseconds (a call to the engine: time moves while a mission reads it)."""
    return round(api.now() * S_TO_NS)


class Clock:
    """A clock: ``now()`` is a :class:`Time` of the engine's clock; ``sleep_for``/``sleep_until`` wait on it."""

    def __init__(self, *, clock_type: ClockType = ClockType.SYSTEM_TIME) -> None:
        self._clock_type = clock_type

    @property
    def clock_type(self) -> ClockType:
        return self._clock_type

    def now(self) -> Time:
        return Time(nanoseconds=now_ns(), clock_type=self._clock_type)

    def sleep_for(self, rel_time: Duration) -> bool:
        api.wait(max(0, rel_time.nanoseconds) / S_TO_NS)
        return True

    def sleep_until(self, until: Time) -> bool:
        api.wait(max(0, until.nanoseconds - now_ns()) / S_TO_NS)
        return True

    def __repr__(self) -> str:
        return f"Clock(clock_type={self._clock_type.name})"


class ROSClock(Clock):
    """A node's clock (``node.get_clock()``): ROS time, which a simulation's nodes take from the simulator."""

    def __init__(self) -> None:
        super().__init__(clock_type=ClockType.ROS_TIME)

    @property
    def ros_time_is_active(self) -> bool:
        return True


__all__ = ["Clock", "ClockType", "ROSClock", "now_ns"]
