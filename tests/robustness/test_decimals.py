"""``aeroexec.decimals.rounded``: ``round(x, digits)`` without its decimal string, the same float bit for bit (what the
event logs, journals and the fleet's messages write must not move by a last bit)."""

import math
import random
import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from aeroexec.decimals import rounded


def _same(made: float, expected: float) -> bool:
    """The same float, bit for bit (the sign of a zero counts), or both NaN; and of the same type."""
    if type(made) is not type(expected):
        return False
    if isinstance(made, float) and math.isnan(made):
        return math.isnan(expected)
    return struct.pack("<d", made) == struct.pack("<d", expected)


@given(st.floats(allow_nan=True, allow_infinity=True) | st.floats(-1e6, 1e6) | st.floats(-2.0, 2.0),
       st.integers(0, 3))
def test_rounded_is_round_for_any_float(x, digits):
    assert _same(rounded(x, digits), round(x, digits))


@pytest.mark.parametrize("digits", [0, 1, 2, 3])
def test_rounded_is_round_at_and_around_every_half_and_near_zero(digits):
    """The halves (the ties ``round`` takes to the even neighbour) and the floats a few units in the last place off
    them, and small numbers of both signs (a zero keeps the sign of what was rounded): the cases where the product
    by 10**digits could be on the wrong side."""
    scale = 10 ** digits
    r = random.Random(digits)
    for _ in range(20_000):
        half = (r.randint(-10**6, 10**6) + 0.5) / scale
        for x in (half, math.nextafter(half, math.inf), math.nextafter(half, -math.inf),
                  half * (1 + 1e-12), half * (1 - 1e-12), r.uniform(-1e-3, 1e-3), -r.uniform(0, 0.6 / scale),
                  r.uniform(-1e4, 1e4)):
            assert _same(rounded(x, digits), round(x, digits)), (x, digits)
    for x in (0.0, -0.0, 5e-324, -5e-324, 999_999.9995, -999_999.9995, 1e6, -1e6, 2.675, 0.125, -0.125):
        assert _same(rounded(x, digits), round(x, digits)), (x, digits)


def test_what_is_not_a_float_under_a_million_is_rounds_own():
    assert _same(rounded(7, 3), round(7, 3))  # an int stays an int
    assert rounded(True, 1) == round(True, 1)
    assert _same(rounded(1234.56789, 5), round(1234.56789, 5))
    assert _same(rounded(3.14159e7, 2), round(3.14159e7, 2))
