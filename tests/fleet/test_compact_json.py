"""The compact JSON encoder made once (the event log's lines, the fleet's messages) writes what json.dumps writes."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from aeroexec.compact_json import compact_encoder

VALUES = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(),
                      lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(), inner, max_size=4),
                      max_leaves=12)


@given(VALUES)
def test_the_text_is_json_dumps_compact(value):
    assert compact_encoder()(value) == json.dumps(value, separators=(",", ":"))


@given(VALUES)
def test_without_nan_the_text_is_json_dumps_or_the_same_refusal(value):
    try:
        expected = json.dumps(value, allow_nan=False, separators=(",", ":"))
    except ValueError:
        with pytest.raises(ValueError):
            compact_encoder(allow_nan=False)(value)
    else:
        assert compact_encoder(allow_nan=False)(value) == expected


def test_a_nan_is_refused_when_not_allowed_and_written_when_it_is():
    with pytest.raises(ValueError):
        compact_encoder(allow_nan=False)({"x": math.nan})
    assert compact_encoder()({"x": math.inf}) == '{"x":Infinity}'
