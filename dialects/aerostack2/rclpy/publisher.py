"""``rclpy.publisher`` as a mission sees it: a publisher of ROS 2 messages used as data, whose every
``publish(msg)`` is an event-log line (``published``, the topic, the message's fields and the mission's line). Nothing
in aeroexec subscribes, as in a ROS 2 graph where nothing listens on that topic. A node's
(``node.create_publisher``) and a drone interface's are this one."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from aeroexec.dialects import ros
from aeroexec.dialects.ros_messages import Message
from aeroexec.engine import api


class Publisher:
    """``publish(msg)`` puts the message in the event log of ``engine()``'s run; a message of another type is a
    TypeError, as rclpy raises."""

    def __init__(self, msg_type: type[Message], topic: str, engine: Callable[[], Any]) -> None:
        self.msg_type, self.topic_name, self._engine = msg_type, topic, engine

    @property
    def topic(self) -> str:
        return self.topic_name

    def publish(self, msg: Message) -> None:
        if not isinstance(msg, self.msg_type):
            raise TypeError(f"Expected {self.msg_type.__name__}, got {type(msg).__name__}")
        engine = self._engine()
        where = api.caller_location()
        detail = repr(msg)
        engine.bridge.call(lambda: engine.log.record("published", self.topic_name, detail, source="mission",
                                                     where=where))

    def get_subscription_count(self) -> int:
        return 0  # nothing in aeroexec subscribes to a mission's topics

    def destroy(self) -> bool:
        return True


def publisher(owner: str, msg_type: Any, topic: str, engine: Callable[[], Any]) -> Publisher:
    """A publisher of ``msg_type`` (a message type used as data) on ``topic`` (resolved already); another type (an
    image, a type of a package aeroexec does not serve) is refused by name, ``owner`` (``Node``,
    ``DroneInterface``) saying whose ``create_publisher`` it was."""
    if not (isinstance(msg_type, type) and issubclass(msg_type, Message)):
        name = (object.__getattribute__(msg_type, "_name") if isinstance(msg_type, ros.Refused)
                else getattr(msg_type, "__name__", repr(msg_type)))
        raise ros.RosFeatureError(f"{owner}.create_publisher of {name}: {ros.ROS2_BEYOND}")
    return Publisher(msg_type, topic, engine)


def resolve_topic(topic: str, namespace: str, node: str | None = None) -> str:
    """The topic's full name, as ROS 2 resolves a relative name in the node's namespace (``~/`` in the node's own)."""
    namespace = "/" + namespace.strip("/") if namespace.strip("/") else ""
    if topic.startswith("/"):
        return topic
    if topic.startswith("~") and node is not None:
        return f"{namespace}/{node}/{topic.removeprefix('~').lstrip('/')}".rstrip("/")
    return f"{namespace}/{topic.removeprefix('~/')}"


__all__ = ["Publisher", "publisher", "resolve_topic"]
