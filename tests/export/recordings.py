"""Reading a recording back for the tests: every message decoded by mcap-ros2-support's decoder and by rosbags'
typestore of ROS 2 Jazzy (its own definitions of the types, not the file's), JSON records parsed."""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.typesys import Stores, get_typestore

JAZZY = get_typestore(Stores.ROS2_JAZZY)


def records(log: Path) -> list[dict]:
    return [json.loads(line) for line in log.read_text().splitlines() if line.strip()]


def read_back(path: Path) -> dict[str, list[tuple[int, object, object]]]:
    """topic -> [(log time, mcap_ros2's decoding or the JSON, rosbags' decoding or None)], every message decoded."""
    decoders = DecoderFactory()
    found: dict[str, list] = defaultdict(list)
    with open(path, "rb") as file:
        reader = make_reader(file)
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if channel.message_encoding == "cdr":
                assert schema.encoding == "ros2msg"
                decoded = decoders.decoder_for("cdr", schema)(message.data)
                found[channel.topic].append((message.log_time, decoded, JAZZY.deserialize_cdr(message.data,
                                                                                               schema.name)))
            else:
                assert (channel.message_encoding, schema.encoding) == ("json", "jsonschema")
                json.loads(schema.data)
                found[channel.topic].append((message.log_time, json.loads(message.data), None))
    return found


def schemas(path: Path) -> dict[str, tuple[str, str]]:
    """topic -> (schema name, schema text)"""
    with open(path, "rb") as file:
        summary = make_reader(file).get_summary()
    return {c.topic: (summary.schemas[c.schema_id].name, summary.schemas[c.schema_id].data.decode())
            for c in summary.channels.values()}


def assert_monotonic(found: dict[str, list]) -> None:
    for topic, messages in found.items():
        times = [t for t, _, _ in messages]
        assert times == sorted(times), topic


def raw(path: Path) -> dict[str, list[tuple[int, bytes]]]:
    """topic -> [(log time, the message's bytes)]"""
    found: dict[str, list] = defaultdict(list)
    with open(path, "rb") as file:
        for _, channel, message in make_reader(file).iter_messages(log_time_order=False):
            found[channel.topic].append((message.log_time, message.data))
    return found
