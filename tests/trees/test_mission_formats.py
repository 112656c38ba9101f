"""The table of mission formats (trees/formats.py): a file's format from its suffix, and for a suffix several
formats share, from its text; every reader, recogniser and writer it names exists; the help's list comes from it."""

from __future__ import annotations

import pytest
from aeroexec.trees import read_mission_tree
from aeroexec.trees.formats import BUILT_IN, described, expected, format_of, formats, writable
from aeroexec.trees.model import TreeFormatError

from aeroexec.plugins import load_reference


@pytest.mark.parametrize(("name", "text", "expected_format"), [
    ("m.py", None, "Python missions"),
    ("m.tml.xml", None, "TML"),
    ("M.XML", None, "BehaviorTree.CPP XML"),
    ("m.yaml", "trees:\n  a: {LAND: {}}\n", "YAML trees"),
    ("m.yml", "nodes:\n  - {node: 1, parent: 0, subtype: task, task: LAND}\n", "Aerostack nodes: YAML"),
    ("m.yaml", "target: drone0\nplan: []\n", "Aerostack2 interpreter plans"),
    ("m.json", '{"anything": 1}', "Aerostack2 interpreter plans"),  # the only format of .json
    ("m.plan", None, "QGroundControl plans"),
    ("m.mission", '{"version": 2, "items": []}', "QGroundControl legacy missions"),
    ("m.mission", "QGC WPL 110\n0\t1\t0\t16\t0\t0\t0\t0\t1\t2\t3\t1\n", "QGC WPL 110 waypoint files"),
    ("m.txt", "anything", "QGC WPL 110 waypoint files"),
    ("m.waypoints", None, "QGC WPL 110 waypoint files"),
])
def test_a_files_format_is_told_by_its_suffix_and_for_a_shared_one_its_text(name, text, expected_format):
    assert format_of(name, text).name == expected_format


def test_a_file_of_no_format_is_none_and_its_error_lists_the_tree_suffixes():
    assert format_of("notes.md", "# hi") is None and format_of("mission", None) is None
    with pytest.raises(TreeFormatError, match=r"unknown mission file type \.md: expected \.tml\.xml, \.xml, .*\.txt"):
        read_mission_tree("# hi", "notes.md")
    with pytest.raises(TreeFormatError, match="a Python mission file is not a behavior tree"):
        read_mission_tree("def mission(): pass\n", "m.py")


def test_every_reference_of_the_table_names_a_function():
    for fmt in formats():
        for reference in (fmt.read, fmt.recognise, fmt.write):
            if reference is not None:
                assert callable(load_reference(reference)), (fmt.name, reference)


def test_each_suffix_is_written_once_per_format_and_the_help_lists_them_all():
    for fmt in BUILT_IN:
        assert len(set(fmt.suffixes)) == len(fmt.suffixes), fmt.name
        assert fmt.shown() in described()
    assert set(writable()) == {"xml", "plan", "waypoints"}
    assert expected().startswith("expected .py, .tml.xml, .xml")
