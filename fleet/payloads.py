"""The fleet link's messages: versioned JSON objects, checked on arrival (a malformed or foreign one is refused).

Every payload is one UTF-8 JSON object with ``"v": VERSION`` and the sender's ``"drone"`` name, which must be
the drone chunk of the key it came on. Keys are ``aeroexec/<fleet>/<drone>/<topic>``:

- ``tick``: what a drone said in one engine period (:func:`tick`: ``said``, its messages ``[topic, fields]`` with
  ``topic`` one of :data:`SAID`, and the wall time it was sent), put at the period's end, on the drone's own key
  (the fleet's router lets only the drone's identity put there);
- ``step``: the end of one engine period of a worker of a fleet spread over worker processes
  (:func:`step`, :mod:`aeroexec.fleet.lockstep`), on the key of the worker's first drone; a tick of such a worker
  says its ``period``;
- ``command``: the operator's queries.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

from aeroexec.compact_json import compact_encoder

VERSION = 2
TOPICS = ("tick", "step", "command")  # the keys' last chunk
SAID = ("telemetry", "events", "beliefs", "broadcast")  # what a drone says in a tick
#: A fleet or drone name: one Zenoh key chunk that is also a portable file name (the drone's output folder, its
#: certificate): a letter, then letters, digits, ``_``, ``-`` or ``.`` (not last). In beliefs a name that is not a
#: bare atom is written quoted (``position('scout-1', P)``).
NAME = re.compile(r"^[A-Za-z](?:[A-Za-z0-9_.-]{0,61}[A-Za-z0-9_-])?$")
NAME_RULE = ("must start with a letter and hold only letters, digits, _, - and . (not last; at most 63), "
             "and cannot be self")
MAX_PAYLOAD = 256 * 1024


class PayloadError(ValueError):
    """A message that is not a fleet message of this version: the text says why, ``reason`` is its kind (the same
    for every message refused for it, so refusals can be counted)."""

    def __init__(self, message: str, reason: str | None = None) -> None:
        super().__init__(message)
        self.reason = reason or message


def key(fleet: str, drone: str, topic: str) -> str:
    """The key expression of ``topic`` for ``drone`` of ``fleet`` (``*`` for every drone)."""
    return f"aeroexec/{fleet}/{drone}/{topic}"


def is_name(name: object) -> bool:
    """True when ``name`` can be a fleet or drone name (see :data:`NAME`)."""
    return isinstance(name, str) and NAME.match(name) is not None and name != "self"


def check_name(name: str, what: str) -> str:
    """``name`` if it can be a fleet or drone name, else ValueError."""
    if not is_name(name):
        raise ValueError(f"{what} {name!r} {NAME_RULE}")
    return name


def encode(drone: str, **fields: Any) -> bytes:
    return _ENCODE({"v": VERSION, "drone": drone, **fields}).encode()


# json.dumps(..., separators=(",", ":")), the same text, by one encoder made once (each drone's tick, every period)
_ENCODE = compact_encoder()


def tick(drone: str, messages: list[list[Any]], sent: float | None = None, period: int | None = None) -> bytes:
    """The ``tick`` payload of ``drone``: its ``messages`` ``[topic, fields]`` of one period (``sent``: the wall time
    it was put, for those who measure the link's latency; ``period``: the period's number, in lockstep)."""
    if period is None:
        return encode(drone, said=messages, sent=sent)
    return encode(drone, said=messages, sent=sent, period=period)


def step(worker: str, period: int, ticks: int, ended: bool, heard: list[str] | None = None) -> bytes:
    """The ``step`` payload of the worker whose first drone is ``worker``: the end of ``period``, in which it put
    ``ticks`` tick messages; ``ended`` when every flight of it has ended; ``heard``: the workers it heard (a hello,
    before the first period)."""
    return encode(worker, period=period, ticks=ticks, ended=ended, heard=heard or [])


def stepped(message: dict[str, Any], key_expr: str) -> tuple[int, int, bool, list[str]]:
    """``(period, ticks, ended, heard)`` of a ``step`` payload; :class:`PayloadError` when it is not one."""
    period, ticks, ended, heard = (message.get(k) for k in ("period", "ticks", "ended", "heard"))
    if not (_count(period, -1) and _count(ticks, 0) and isinstance(ended, bool) and isinstance(heard, list)
            and all(isinstance(h, str) for h in heard)):
        raise PayloadError(f"{key_expr}: not a step (expected period, ticks, ended, heard)", "not a step")
    return period, ticks, ended, heard


def period_of(message: dict[str, Any], key_expr: str) -> int:
    """The period a worker's tick says it belongs to; :class:`PayloadError` when it says none."""
    period = message.get("period")
    if not _count(period, 0):
        raise PayloadError(f"{key_expr}: a worker's tick without its period", "a worker's tick without its period")
    return period


def _count(value: Any, least: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and least <= value < 1 << 62


def said(message: dict[str, Any], key_expr: str) -> list[tuple[str, dict[str, Any]]]:
    """The ``(topic, fields)`` of a ``tick`` payload; :class:`PayloadError` when it is not one."""
    messages = message.get("said")
    if not isinstance(messages, list):
        raise PayloadError(f"{key_expr}: not a tick (expected said: [[topic, fields]...])", "not a tick")
    out = []
    for item in messages:
        if not (isinstance(item, list) and len(item) == 2 and item[0] in SAID and isinstance(item[1], dict)):
            raise PayloadError(f"{key_expr}: {str(item)[:200]} is not [topic, fields] (topics: {', '.join(SAID)})",
                               "a malformed message in a tick")
        out.append((item[0], item[1]))
    return out


def decode(key_expr: str, payload: bytes, fleet: str) -> tuple[str, str, dict[str, Any]]:
    """``(drone, topic, message)`` of a sample on ``key_expr``; :class:`PayloadError` when it is not one of ours."""
    parts = str(key_expr).split("/")
    if len(parts) != 4 or parts[0] != "aeroexec" or parts[1] != fleet or parts[3] not in TOPICS:
        raise PayloadError(f"foreign key {key_expr}", "not a key of the fleet's")
    drone, topic = parts[2], parts[3]
    if not is_name(drone):
        raise PayloadError(f"{key_expr}: {drone!r} is no drone name", "not a drone's key")
    if len(payload) > MAX_PAYLOAD:
        raise PayloadError(f"{len(payload)} bytes on {key_expr}: more than {MAX_PAYLOAD}", "too large")
    try:
        message = json.loads(payload)
    except (ValueError, UnicodeDecodeError) as exc:
        raise PayloadError(f"not JSON on {key_expr}: {exc}", "not JSON") from None
    except RecursionError:
        raise PayloadError(f"JSON nested too deep on {key_expr}", "not JSON") from None
    if not isinstance(message, dict):
        raise PayloadError(f"not a JSON object on {key_expr}", "not a JSON object")
    if message.get("v") != VERSION:
        raise PayloadError(f"version {message.get('v')!r} on {key_expr}: this engine reads version {VERSION}",
                           "another version of the fleet's messages")
    if message.get("drone") != drone:
        raise PayloadError(f"a message on {key_expr} says it is from {message.get('drone')!r}",
                           "says it is from another drone than its key")
    return drone, topic, message


def vector(value: Any, size: int = 3) -> tuple[float, ...]:
    """A list of ``size`` finite numbers as a tuple; PayloadError otherwise."""
    if size == 3 and type(value) is list and len(value) == 3:  # a position, a velocity: three floats, as said
        x, y, z = value
        if type(x) is float and type(y) is float and type(z) is float and _finite(x) and _finite(y) and _finite(z):
            return x, y, z
    if not isinstance(value, list) or len(value) != size:
        raise _not_numbers(value, size)
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise _not_numbers(value, size)
        try:
            number = float(v)
        except OverflowError:  # an integer no float holds
            raise _not_numbers(value, size) from None
        if not math.isfinite(number):
            raise _not_numbers(value, size)
        out.append(number)
    return tuple(out)


_finite = math.isfinite


def _not_numbers(value: Any, size: int) -> PayloadError:
    """:func:`vector`'s refusal, made only when it refuses (every telemetry message reads two vectors)."""
    return PayloadError(f"expected {size} finite numbers, got {str(value)[:200]}", f"not {size} numbers")
