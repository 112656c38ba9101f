"""JSON whose objects know the line they start on, so a mission file's problems can name file:line."""

from __future__ import annotations

import bisect
import json
import json.scanner
from typing import Any

from aeroexec.trees.model import TreeFormatError

from aeroexec.limits import MAX_NESTING, MAX_NUMBER_LENGTH, line_of_offset, nesting_beyond


class Lined(dict):
    """A JSON object that knows the line it starts on."""

    line = 0


def _number(text: str, kind: type) -> Any:
    if len(text) > MAX_NUMBER_LENGTH:
        raise _TooLong(text)
    return kind(text)


class _TooLong(ValueError):
    """A number longer than the readers' limit (a 5,000-digit integer would cost the parser seconds)."""


def parse_json(text: str, file: str) -> Any:
    """JSON whose objects are :class:`Lined` dicts; a syntax error, nesting deeper than ``MAX_NESTING`` or a number
    longer than ``MAX_NUMBER_LENGTH`` is a TreeFormatError at its line."""
    deep = nesting_beyond(text, MAX_NESTING, "[{", "]}", '"')
    if deep is not None:
        raise TreeFormatError([(file, line_of_offset(text, deep), f"not a mission: it nests deeper than "
                                                                   f"{MAX_NESTING} levels")])
    newlines = [i for i, c in enumerate(text) if c == "\n"]
    decoder = json.JSONDecoder(parse_int=lambda t: _number(t, int), parse_float=lambda t: _number(t, float))
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
    except _TooLong as error:
        number = str(error)
        raise TreeFormatError([(file, line_of_offset(text, text.find(number)),
                                f"a number of {len(number)} characters: numbers have {MAX_NUMBER_LENGTH} at most")]) \
            from None
