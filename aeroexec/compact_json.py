"""JSON text as ``json.dumps(value, separators=(",", ":"))`` writes it, by one encoder made once.

``json.dumps`` with options makes a new ``JSONEncoder`` at every call, and ``JSONEncoder.encode`` a new C encoder:
for what is written every period of every drone (the event log's lines, the fleet's messages) the C encoder is made
once here. It is made without the check for circular references (a dictionary shared between calls): the values
given are made afresh, plain and acyclic. Where json has no C encoder, json's own encoder writes the same text.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any


def compact_encoder(allow_nan: bool = True) -> Callable[[Any], str]:
    """A function writing a value as ``json.dumps(value, allow_nan=allow_nan, separators=(",", ":"))`` does."""
    options = json.JSONEncoder(allow_nan=allow_nan, separators=(",", ":"))
    make = json.encoder.c_make_encoder
    if make is None:
        return options.encode
    encode = make(None, options.default, json.encoder.encode_basestring_ascii, None, ":", ",", False, False,
                  allow_nan)
    return lambda value: "".join(encode(value, 0))
