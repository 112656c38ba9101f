"""The fleet link's messages: versioned JSON objects, checked on arrival (a malformed or foreign one is refused).

Every payload is one UTF-8 JSON object with ``"v": VERSION`` and the sender's ``"drone"`` name, which must be
the drone chunk of the key it came on. Keys are ``aeroexec/<fleet>/<drone>/<topic>``.
"""

from __future__ import annotations

import json
import re
from typing import Any

VERSION = 1
TOPICS = ("telemetry", "events", "beliefs", "broadcast", "command")
NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,62}$")  # a fleet or drone name: one key chunk, a belief atom
MAX_PAYLOAD = 256 * 1024


class PayloadError(ValueError):
    """A message that is not a fleet message of this version (the text says why)."""


def key(fleet: str, drone: str, topic: str) -> str:
    """The key expression of ``topic`` for ``drone`` of ``fleet`` (``*`` for every drone)."""
    return f"aeroexec/{fleet}/{drone}/{topic}"


def check_name(name: str, what: str) -> str:
    """``name`` if it can be a fleet or drone name (a letter, then letters, digits or _), else ValueError."""
    if not isinstance(name, str) or not NAME.match(name) or name == "self":
        raise ValueError(f"{what} {name!r} must start with a letter and hold only letters, digits and _ "
                         f"(at most 63), and cannot be self")
    return name


def encode(drone: str, **fields: Any) -> bytes:
    return json.dumps({"v": VERSION, "drone": drone, **fields}, separators=(",", ":")).encode()


def decode(key_expr: str, payload: bytes, fleet: str) -> tuple[str, str, dict[str, Any]]:
    """``(drone, topic, message)`` of a sample on ``key_expr``; :class:`PayloadError` when it is not one of ours."""
    parts = str(key_expr).split("/")
    if len(parts) != 4 or parts[0] != "aeroexec" or parts[1] != fleet or parts[3] not in TOPICS:
        raise PayloadError(f"foreign key {key_expr}")
    drone, topic = parts[2], parts[3]
    if not NAME.match(drone) or drone == "self":
        raise PayloadError(f"{key_expr}: {drone!r} is no drone name")
    if len(payload) > MAX_PAYLOAD:
        raise PayloadError(f"{len(payload)} bytes on {key_expr}: more than {MAX_PAYLOAD}")
    try:
        message = json.loads(payload)
    except (ValueError, UnicodeDecodeError) as exc:
        raise PayloadError(f"not JSON on {key_expr}: {exc}") from None
    if not isinstance(message, dict):
        raise PayloadError(f"not a JSON object on {key_expr}")
    if message.get("v") != VERSION:
        raise PayloadError(f"version {message.get('v')!r} on {key_expr}: this engine reads version {VERSION}")
    if message.get("drone") != drone:
        raise PayloadError(f"a message on {key_expr} says it is from {message.get('drone')!r}")
    return drone, topic, message


def vector(value: Any, size: int = 3) -> tuple[float, ...]:
    """A list of ``size`` finite numbers as a tuple; PayloadError otherwise."""
    if not isinstance(value, list) or len(value) != size:
        raise PayloadError(f"expected {size} numbers, got {value!r}")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, int | float) or v != v or abs(v) == float("inf"):
            raise PayloadError(f"expected {size} numbers, got {value!r}")
        out.append(float(v))
    return tuple(out)
