"""``rclpy.duration``: :class:`~aeroexec.dialects.aerostack2.rclpy.time.Duration`."""

from aeroexec.dialects.aerostack2.rclpy.time import Duration

__all__ = ["Duration"]
