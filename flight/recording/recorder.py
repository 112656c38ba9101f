"""A run's records made messages: each record of the event log (a finished run's, or the live stream's) goes to
the topics the table gives its kind (``topics.py``), encoded once (ROS 2 types in CDR by mcap's ROS 2 support,
aeroexec's records as JSON) and handed to every sink (an MCAP file, a live view).

Times: a record's engine time in nanoseconds from the run's start (the log's ``wall_time`` on a wall clock; 0 on a
simulated clock, so a simulated run's recording is the same in every replay), never before 0 and never going back on
a topic (an event restamped to an earlier time keeps its topic's last time as the message's log time; its header
keeps its own).
"""

from __future__ import annotations

import datetime
import json
from collections import Counter
from collections.abc import Callable
from typing import Any, Protocol

from aeroexec.flight.recording.ros_messages import message_definition
from aeroexec.flight.recording.topics import JSON_SCHEMAS, META_KINDS, TOPICS, Drone, Topic, topics_of

from aeroexec.extras import require


class Sink(Protocol):
    """Where messages go: an MCAP file, a live view."""

    def channel(self, topic: str, schema: str, schema_encoding: str, schema_data: bytes, message_encoding: str,
                metadata: dict[str, str] | None = None) -> Any: ...

    def write(self, channel: Any, log_time: int, data: bytes) -> None: ...

    def metadata(self, name: str, values: dict[str, Any]) -> None: ...

    def close(self, keep: bool = True) -> None: ...


def start_ns(meta: dict[str, Any]) -> int:
    """The run's start in ns since the epoch: its log's ``wall_time`` (a wall clock's), else 0 (a simulated one)."""
    wall = meta.get("wall_time")
    if not isinstance(wall, str):
        return 0
    try:
        return int(datetime.datetime.fromisoformat(wall).timestamp()) * 1_000_000_000
    except ValueError:
        return 0


class Recorder:
    """Records in, messages out to ``sinks``; :attr:`counts` says how many went to each topic."""

    def __init__(self, sinks: list[Sink]) -> None:
        with require("ros"):
            from mcap_ros2._dynamic import serialize_dynamic
        self._serialize = serialize_dynamic
        self.sinks = list(sinks)
        self.counts: Counter[str] = Counter()
        self._channels: dict[str, list[Any]] = {}
        self._last: dict[str, int] = {}
        self._encoders: dict[str, Callable[[Any], bytes]] = {}

    def declare(self, drone: Drone) -> None:
        """Open every topic ``drone`` has now, before its records: a live view advertises them all at once, to a
        viewer that connects before the flight."""
        for topic in TOPICS:
            if topic.has(drone):
                self._channel(topic.topic(drone), topic)

    def record(self, drone: Drone, record: dict[str, Any]) -> None:
        """The messages of one record of ``drone``'s log. Raises KeyError, TypeError or ValueError for a record
        that lacks what its topics need (the caller names its file and line)."""
        kind = record.get("kind")
        if not isinstance(kind, str) or kind in META_KINDS:
            return
        ns = max(0, drone.start_ns + round(float(record["time"]) * 1e9))
        for topic in topics_of(kind):
            message = topic.message(record, drone, ns)
            if message is None:
                continue
            name = topic.topic(drone)
            log_time = max(ns, self._last.get(name, 0))
            self._last[name] = log_time
            data = self._encode(topic, message)
            for sink, channel in zip(self.sinks, self._channel(name, topic), strict=True):
                sink.write(channel, log_time, data)
            self.counts[name] += 1

    def metadata(self, name: str, values: dict[str, Any]) -> None:
        for sink in self.sinks:
            sink.metadata(name, values)

    def close(self, keep: bool = True) -> None:
        """Close every sink (each on its own: one that fails never keeps the others open)."""
        errors = []
        for sink in self.sinks:
            try:
                sink.close(keep)
            except Exception as error:  # noqa: BLE001 -- raised after the others are closed
                errors.append(error)
        if errors:
            raise errors[0]

    def _channel(self, name: str, topic: Topic) -> list[Any]:
        channels = self._channels.get(name)
        if channels is None:
            if topic.encoding == "cdr":
                schema = ("ros2msg", message_definition(topic.schema).encode())
            else:
                schema = ("jsonschema", json.dumps(JSON_SCHEMAS[topic.schema]).encode())
            channels = self._channels[name] = [sink.channel(name, topic.schema, *schema, topic.encoding)
                                               for sink in self.sinks]
        return channels

    def _encode(self, topic: Topic, message: Any) -> bytes:
        if topic.encoding == "json":
            return json.dumps(message, separators=(",", ":")).encode()
        encoder = self._encoders.get(topic.schema)
        if encoder is None:
            encoder = self._encoders[topic.schema] = self._serialize(topic.schema,
                                                                     message_definition(topic.schema))[topic.schema]
        return encoder(message)


__all__ = ["Recorder", "Sink", "start_ns"]
