"""``round(x, digits)`` of the numbers a fleet drone writes every period (its telemetry message, its event log's and
journal's times and samples), the same float bit for bit, without ``round``'s decimal string.

Python's ``round(x, 3)`` writes ``x`` as a correctly rounded decimal string and reads it back (``_Py_dg_dtoa``,
``snprintf``, ``_Py_dg_strtod``: ~4,800 instructions). :func:`rounded` finds the same integer of thousandths from
``x * 1000``, whose error is at most half a unit in its last place: unless that product is within 1e-4 of a half
(a tie, or near one: then ``round`` itself answers), the nearest integer to it is the nearest integer to the exact
product, and that integer divided by 1000 (both exact, the quotient rounded once by IEEE division) is the float
nearest to the decimal ``round`` reads back. A result of zero keeps ``x``'s sign, as ``round`` does. Anything else
(not a float, not finite, a million or more, other digits) is ``round``'s.
"""

from __future__ import annotations

import math

_SCALES = (1.0, 10.0, 100.0, 1000.0)  # 10 ** digits, exact
_floor = math.floor
_copysign = math.copysign


def rounded(x: float, digits: int) -> float:
    """``round(x, digits)``, the same float, made without a decimal string for a float under a million in size and
    0 to 3 digits."""
    if type(x) is float and -1e6 < x < 1e6 and 0 <= digits <= 3:
        scale = _SCALES[digits]
        scaled = x * scale
        whole = _floor(scaled)
        part = scaled - whole  # the product's fraction (exact but for a product in (-1, 0), far from a half)
        if part < 0.4999:
            return whole / scale if whole else _copysign(0.0, x)
        if part > 0.5001:
            whole += 1
            return whole / scale if whole else _copysign(0.0, x)
    return round(x, digits)


__all__ = ["rounded"]
