"""A Python mission's source read into its AST (``engine/missions/source.py``): a run asks for its mission's AST
several times (whether it is a script of several drones, its check, whether to run it as a script) and it is
parsed once."""

from __future__ import annotations

import ast

import pytest
from aeroexec.engine.missions.source import parse_source


def test_the_same_text_of_the_same_file_is_parsed_once():
    source = "def mission():\n    execute_behavior('TAKE_OFF')\n"
    tree = parse_source(source, "m.py")
    assert isinstance(tree, ast.Module) and parse_source(source, "m.py") is tree
    assert parse_source(source, "other.py") is not tree  # another file's: its own AST
    changed = parse_source(source + "    execute_behavior('LAND')\n", "m.py")
    assert changed is not tree and len(changed.body[0].body) == 2


def test_a_source_that_cannot_be_read_is_refused_every_time_with_its_line():
    for _ in range(2):
        with pytest.raises(SyntaxError) as refused:
            parse_source("def mission():\n    x = (\n", "broken.py")
        assert refused.value.filename == "broken.py" and refused.value.lineno == 2
