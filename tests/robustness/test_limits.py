"""The readers' documented limits (docs/reference/limits.md): at the limit an input is read, one past it
is refused with the file and line; special files are refused unread; anonymous variables cannot be written."""

from __future__ import annotations

import os

import pytest
from aeroexec.beliefs import BeliefMemory, BeliefSyntaxError, Var, parse_expression
from aeroexec.engine.catalog.behavior_catalog import default_catalog
from aeroexec.engine.missions.check import check_mission_source
from aeroexec.engine.supervision.operator import OperatorError, ScriptedOperator
from aeroexec.flight.missions import check_mission
from aeroexec.trees import TreeFormatError, load_mission_tree

from aeroexec.limits import (
    MAX_FILE_BYTES,
    MAX_LITERALS,
    MAX_NESTING,
    MAX_NUMBER_LENGTH,
    MAX_TERM_DEPTH,
    MAX_TREE_NODES,
    MAX_YAML_NODES,
    InputError,
    compose_yaml,
    read_bytes,
)


def test_a_file_at_the_size_limit_is_read_and_one_byte_more_is_refused(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"#" * MAX_FILE_BYTES)
    assert len(read_bytes(path)) == MAX_FILE_BYTES
    path.write_bytes(b"#" * (MAX_FILE_BYTES + 1))
    with pytest.raises(InputError, match=f"big.yaml: the file is {MAX_FILE_BYTES + 1:,} bytes, more than the limit"):
        read_bytes(path)


def test_devices_fifos_and_directories_are_refused_before_reading(tmp_path):
    with pytest.raises(InputError, match="/dev/zero: not a regular file: it is a character device"):
        read_bytes("/dev/zero")  # reading it would never end
    os.mkfifo(tmp_path / "pipe.xml")
    with pytest.raises(TreeFormatError, match="pipe.xml: not a regular file: it is a FIFO"):
        load_mission_tree(tmp_path / "pipe.xml")
    with pytest.raises(InputError, match="it is a directory"):
        read_bytes(tmp_path)


def nested(depth: int) -> str:
    return "a: " + "[" * (depth - 1) + "x" + "]" * (depth - 1) + "\n"  # the mapping is the first level


def test_yaml_nesting_at_the_limit_is_read_and_deeper_is_refused_with_its_line():
    assert compose_yaml(nested(MAX_NESTING), "f.yaml") is not None
    with pytest.raises(InputError, match=f"f.yaml:2: not valid YAML: nested more than {MAX_NESTING} levels deep"):
        compose_yaml("b: 1\n" + nested(MAX_NESTING + 1), "f.yaml")


def test_yaml_values_are_counted_with_aliases_where_they_are_used():
    flat = "a: [" + ", ".join(["1"] * (MAX_YAML_NODES - 3)) + "]\n"  # the mapping, its key and the list
    assert compose_yaml(flat, "f.yaml") is not None
    with pytest.raises(InputError, match=f"more than {MAX_YAML_NODES:,} values"):
        compose_yaml(flat.replace("[1,", "[1, 1,"), "f.yaml")
    bomb = "a: &a [" + ", ".join(["x"] * 60) + "]\n" + "".join(
        f"{k}: &{k} [" + ", ".join([f"*{p}"] * 60) + "]\n" for p, k in zip("abc", "bcd", strict=True))
    with pytest.raises(InputError, match=f"f.yaml:3: not valid YAML: more than {MAX_YAML_NODES:,} values"):
        compose_yaml(bomb, "f.yaml")
    with pytest.raises(InputError, match=r"the alias \*a is inside its own anchor"):
        compose_yaml("a: &a [1, *a]\n", "f.yaml")


def test_numbers_up_to_the_length_limit_are_read():
    assert compose_yaml("a: " + "1" * MAX_NUMBER_LENGTH, "f.yaml") is not None
    with pytest.raises(InputError, match=f"f.yaml:1: .*{MAX_NUMBER_LENGTH + 1} characters is longer than the limit"):
        compose_yaml("a: " + "1" * (MAX_NUMBER_LENGTH + 1), "f.yaml")


def test_xml_trees_nest_up_to_the_limit(tmp_path):
    def tree(inverters: int) -> str:  # <root>, <BehaviorTree> and the leaf around the inverters
        return ('<root BTCPP_format="4"><BehaviorTree ID="M">' + "<ForceSuccess>" * inverters + "<LAND/>"
                + "</ForceSuccess>" * inverters + "</BehaviorTree></root>")

    path = tmp_path / "deep.xml"
    path.write_text(tree(MAX_NESTING - 3))
    assert load_mission_tree(path).root.type == "ForceSuccess"
    path.write_text(tree(MAX_NESTING - 2))
    with pytest.raises(TreeFormatError, match=f"deep.xml:1: <LAND> is nested more than {MAX_NESTING} elements"):
        load_mission_tree(path)


def test_python_missions_nest_up_to_the_limit():
    def mission(depth: int) -> str:
        return "def mission():\n    x = " + "[" * depth + "]" * depth + "\n"

    assert not [p for p in check_mission_source(mission(MAX_NESTING - 10), "m.py") if "nested" in p.message]
    problems = check_mission_source(mission(MAX_NESTING + 10), "m.py")
    assert [(p.line, p.kind) for p in problems if "nested more than" in p.message] == [(2, "WRONG_FORMAT")]


def test_belief_terms_and_conjunctions_up_to_their_limits():
    parse_expression("p(" + "[" * (MAX_TERM_DEPTH - 1) + "x" + "]" * (MAX_TERM_DEPTH - 1) + ")")
    with pytest.raises(BeliefSyntaxError, match=f"nested more than {MAX_TERM_DEPTH} levels deep at column"):
        parse_expression("p(" + "[" * MAX_TERM_DEPTH + "x" + "]" * MAX_TERM_DEPTH + ")")
    with pytest.raises(BeliefSyntaxError, match=f"more than the limit of {MAX_LITERALS}"):
        parse_expression(", ".join(["p(x)"] * (MAX_LITERALS + 1)))
    with pytest.raises(BeliefSyntaxError, match="is longer than the limit"):
        parse_expression("p(" + "1" * (MAX_NUMBER_LENGTH + 1) + ")")


def test_a_user_variable_is_never_an_anonymous_one():
    memory = BeliefMemory()
    memory.add("p(a, b)")
    anonymous = [Var("?") for _ in range(200)]
    assert all(v.anonymous and "#" in v.name for v in anonymous)  # "#" cannot be written in a variable
    assert memory.query_all("p(?, ?_167)") == [{"?_167": "b"}]
    assert memory.query_all("p(?_1, ?_1)") == []  # one named variable, twice: a and b differ
    assert not Var("?_167").anonymous


def test_a_mission_with_a_depth_at_the_limit_verifies(tmp_path):
    path = tmp_path / "deep.yaml"
    body, depth = "LAND", 0
    while depth < MAX_NESTING // 2 - 4:  # each node is a mapping holding a mapping: two levels per node
        body, depth = {"ForceSuccess": {"child": body}}, depth + 1
    import yaml

    path.write_text(yaml.safe_dump({"tree": {"Sequence": {"children": [{"TAKE_OFF": {"ALTITUDE": 2}}, body]}}}))
    assert not check_mission(path, default_catalog()).errors


def test_an_answers_file_is_read_within_the_limits(tmp_path):
    path = tmp_path / "answers.yaml"
    path.write_text("Fly east?: " + "[" * 500 + "]" * 500 + "\n")
    with pytest.raises(OperatorError, match=f"answers.yaml:1: not valid YAML: nested more than {MAX_NESTING}"):
        ScriptedOperator.from_file(path)


def test_an_event_log_that_is_a_fifo_or_too_deep_is_refused(tmp_path):
    from aeroexec.flight.flight_log import read_flight_log

    os.mkfifo(tmp_path / "events.jsonl")
    with pytest.raises(ValueError, match="not a regular file: it is a FIFO"):
        read_flight_log(tmp_path / "events.jsonl")
    deep = tmp_path / "deep.jsonl"
    deep.write_text('{"kind": "engine_started"}\n' + "[" * 60_000 + "\n{}\n")
    with pytest.raises(ValueError, match=f"deep.jsonl:2: nested more than {MAX_NESTING} levels deep"):
        read_flight_log(deep)


def test_subtrees_used_many_times_are_checked_once_and_an_expansion_bomb_is_refused(tmp_path):
    def trees(levels: int, uses: int) -> str:
        body = "".join(f'<BehaviorTree ID="T{i}"><Sequence>' + f'<SubTree ID="T{i + 1}"/>' * uses
                       + "</Sequence></BehaviorTree>" for i in range(levels))
        return (f'<root BTCPP_format="4" main_tree_to_execute="T0">{body}<BehaviorTree ID="T{levels}">'
                f'<WAIT DURATION="1"/></BehaviorTree></root>')

    path = tmp_path / "bomb.xml"
    path.write_text(trees(3, 30))  # 27,000 WAIT leaves once expanded: verified, each tree walked once
    assert not check_mission(path, default_catalog()).errors
    path.write_text(trees(6, 10))  # a million leaves: refused at the main tree
    errors = check_mission(path, default_catalog()).errors
    assert [(e.line, e.message) for e in errors] == [(1, f"The mission has more than {MAX_TREE_NODES:,} nodes once "
                                                        "its SubTrees are expanded where they are used (the limit "
                                                        "of the readers)")]
    path.write_text(trees(MAX_NESTING, 1))  # a chain of SubTrees deeper than the limit
    assert [e.message for e in check_mission(path, default_catalog()).errors] == [
        f"The mission is nested more than {MAX_NESTING} levels deep once its SubTrees are expanded where they are "
        "used (the limit of the readers)"]


def test_a_script_at_the_nesting_limit_runs_and_one_operator_more_is_refused_with_its_line(tmp_path):
    from aeroexec.trees.script import ScriptError, compile_script

    def chain(operators: int) -> str:  # the script's statement and assignment are two levels, the value one more
        return "a := " + " + ".join(["1"] * (operators + 1))

    assert compile_script(chain(MAX_NESTING - 3)).run({}) == MAX_NESTING - 2
    with pytest.raises(ScriptError, match=f"nested more than {MAX_NESTING} levels deep"):
        compile_script(chain(MAX_NESTING - 2))
    path = tmp_path / "deep_script.xml"  # found by the fuzz suite: a 1,000-term chain overflowed Python's stack
    path.write_text('<root BTCPP_format="4"><BehaviorTree ID="M">\n<Sequence>\n'
                    f'<Script code="s := {" .. ".join(["x"] * 1000)}"/>\n</Sequence></BehaviorTree></root>\n')
    errors = check_mission(path, default_catalog()).errors
    assert [(e.line, f"nested more than {MAX_NESTING} levels deep" in e.message) for e in errors] == [(3, True)]
