"""JSON whose objects know the line they start on, so a mission file's problems can name file:line."""

from __future__ import annotations

import bisect
import json
import json.scanner
from typing import Any

from aeroexec.trees.model import TreeFormatError


class Lined(dict):
    """A JSON object that knows the line it starts on."""

    line = 0


def parse_json(text: str, file: str) -> Any:
    """JSON whose objects are :class:`Lined` dicts; a syntax error is a TreeFormatError at its line."""
    newlines = [i for i, c in enumerate(text) if c == "\n"]
    decoder = json.JSONDecoder()
    plain = decoder.parse_object

    def parse_object(s_and_end: tuple[str, int], *args: Any) -> tuple[Any, int]:
        value, end = plain(s_and_end, *args)
        lined = Lined(value)
        lined.line = bisect.bisect_left(newlines, s_and_end[1]) + 1
        return lined, end

    decoder.parse_object = parse_object  # type: ignore[assignment]
    decoder.scan_once = json.scanner.py_make_scanner(decoder)  # the Python scanner calls parse_object
    try:
        return decoder.decode(text)
    except json.JSONDecodeError as error:
        raise TreeFormatError([(file, error.lineno, f"not JSON: {error.msg} (column {error.colno})")]) from None
