"""The values a mission handles (call arguments and results, blackboard entries) as JSON and back, exactly: a
tuple comes back a tuple, an Outcome an Outcome, a unification a unification, a belief term a term.

JSON keeps ``None``, booleans, integers, finite floats, strings and lists as they are; every other value is an
object with one tagged key (``{"tuple": [...]}``, ``{"dict": [[key, value], ...]}``, ``{"outcome": "..."}``...).
A value of no known kind is kept as its text (``{"text": repr}``) and comes back as that text. :func:`canonical`
is the one text of a value (sorted keys, no spaces): two calls with equal arguments have equal texts.
"""

from __future__ import annotations

import enum
import json
import math

from aeroexec.beliefs import Struct, format_term, parse_term
from aeroexec.engine.api import Unification
from aeroexec.engine.events import Outcome

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

def encode(value: Any) -> Any:
    """``value`` as JSON-able data (see the module's docstring)."""
    if isinstance(value, Outcome):  # a str too: looked at first
        return {"outcome": value.value}
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return value if math.isfinite(value) else {"float": repr(value)}
    if isinstance(value, enum.Enum):
        return encode(value.value)
    if isinstance(value, Struct):
        return {"term": format_term(value)}
    if isinstance(value, list):
        return [encode(v) for v in value]
    if isinstance(value, tuple):
        return {"tuple": [encode(v) for v in value]}
    if isinstance(value, set | frozenset):
        return {"set": sorted((encode(v) for v in value), key=canonical)}
    if isinstance(value, dict):
        tag = "unification" if type(value).__name__ == "Unification" else "dict"
        return {tag: [[encode(k), encode(v)] for k, v in value.items()]}
    tolist = getattr(value, "tolist", None)  # numpy values
    if callable(tolist):
        return encode(tolist())
    return {"text": repr(value)}


def decode(data: Any) -> Any:
    """The value :func:`encode` gave ``data`` for."""
    if isinstance(data, list):
        return [decode(v) for v in data]
    if not isinstance(data, dict):
        return data
    (tag, inner), = data.items()
    if tag == "tuple":
        return tuple(decode(v) for v in inner)
    if tag == "dict":
        return {decode(k): decode(v) for k, v in inner}
    if tag == "unification":
        return Unification({decode(k): decode(v) for k, v in inner})
    if tag == "outcome":
        return Outcome(inner)
    if tag == "term":
        return parse_term(inner)
    if tag == "set":
        return {decode(v) for v in inner}
    if tag == "float":
        return float(inner)
    return inner  # "text": kept as its text


def dumps(value: Any) -> str:
    """:func:`encode` as JSON text."""
    return json.dumps(encode(value), separators=(",", ":"), allow_nan=False)


def loads(text: str | None) -> Any:
    """The value of :func:`dumps`'s text (None for None)."""
    return None if text is None else decode(json.loads(text))


def canonical(data: Any) -> str:
    """The one text of encoded data (keys sorted, no spaces)."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)


_SCALARS = frozenset({str, int, float, bool, type(None)})
_TEXTS: dict[Any, str] = {}


def text(value: Any) -> str:
    """``canonical(encode(value))``, remembered for the scalars a mission gets again and again (a polling loop's
    answers)."""
    kind = type(value)
    if kind in _SCALARS:
        key = (kind, value)
        found = _TEXTS.get(key)
        if found is None:
            found = canonical(encode(value))
            if len(_TEXTS) < 4096:
                _TEXTS[key] = found
        return found
    return canonical(encode(value))


def call_text(args: tuple, kwargs: dict[str, Any]) -> str:
    """The one text of a call's arguments (``[args, kwargs]`` encoded), remembered when they are all scalars."""
    if not kwargs and len(args) == 1 and type(args[0]) is str:  # a behavior's name, a belief: the usual call
        key: tuple = args
    else:
        kinds = tuple(map(type, args))
        if kwargs or not _SCALARS.issuperset(kinds):
            return canonical(encode([list(args), kwargs]))
        key = (args, kinds)  # the kinds too: 1, 1.0 and True are equal keys but three texts
    found = _TEXTS.get(key)
    if found is None:
        found = canonical(encode([list(args), kwargs]))
        if len(_TEXTS) < 4096:
            _TEXTS[key] = found
    return found


__all__ = ["call_text", "canonical", "decode", "dumps", "encode", "loads", "text"]
