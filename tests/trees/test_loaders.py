"""Mission-file loaders: XML (BehaviorTree.CPP v4), nested YAML and Aerostack's flat YAML into the tree model."""

from __future__ import annotations

from pathlib import Path

import pytest
from aeroexec.trees import TreeFormatError, TreeNode, load_mission_tree, read_mission_tree

DATA = Path(__file__).parent / "data"


def shape(node: TreeNode) -> tuple:
    """A node without its place: what must be equal whatever the format."""
    return node.type, node.name, node.ports, [shape(child) for child in node.children]


def problems(text: str, file: str) -> list[tuple[str, int, str]]:
    with pytest.raises(TreeFormatError) as caught:
        read_mission_tree(text, file)
    return caught.value.problems


def only_problem(text: str, file: str) -> tuple[int, str]:
    found = problems(text, file)
    assert len(found) == 1, found
    assert found[0][0] == file
    return found[0][1], found[0][2]


# -- one mission, three formats ------------------------------------------------------------------
def test_xml_and_both_yaml_forms_give_the_same_model():
    xml = load_mission_tree(DATA / "inspection.xml")
    nested = load_mission_tree(DATA / "inspection.yaml")
    flat = load_mission_tree(DATA / "inspection_aerostack.yaml")
    assert xml.main == nested.main == flat.main == "MainTree"
    assert shape(xml.root) == shape(nested.root) == shape(flat.root)
    path = xml.root.children[2]
    assert (path.type, path.ports) == ("FOLLOW_PATH", {"PATH": "[[0, 0, 1], [{X}, {Y}, 1.5]]"})
    assert xml.root.children[3].children[0].ports == {"ANGLE": "180", "_wait_for_completion": "false"}


def test_xml_lines_are_those_of_the_elements():
    document = load_mission_tree(DATA / "inspection.xml")
    assert document.lines == {"MainTree": 4}
    root = document.root
    assert (root.type, root.line, root.file) == ("Sequence", 5, str(DATA / "inspection.xml"))
    assert [child.line for child in root.children] == [6, 7, 8, 9, 12, 18, 23]
    assert root.children[5].children[0].children[0].line == 20
    assert root.children[5].children[0].children[0].where == f"{DATA / 'inspection.xml'}:20"


def test_yaml_lines_are_those_of_the_node_types():
    nested = load_mission_tree(DATA / "inspection.yaml")
    assert nested.lines == {"MainTree": 4}
    assert nested.root.line == 5
    assert [child.line for child in nested.root.children] == [8, 9, 10, 13, 18, 27, 33]
    flat = load_mission_tree(DATA / "inspection_aerostack.yaml")
    assert [child.line for child in flat.root.children] == [9, 17, 24, 33, 49, 77, 92]
    note, inverter = flat.root.children[4].children  # node 8 is written after node 9 but comes first
    assert (note.name, note.line, inverter.name, inverter.line) == ("Note", 62, "Not", 56)


def test_yaml_values_become_port_text_as_xml_writes_it():
    document = read_mission_tree(
        "tree:\n"
        "  Sequence:\n"
        "    - GO_TO_POINT: {COORDINATES: {P}, SPEED: 1.50}\n"
        "    - SPEAK: {TEXT: 'hello, world', WORDS: [a, 'b, c', '{K}']}\n"
        "    - Condition: battery(self, low)\n"
        "    - Action: {ID: LAND, name: down}\n"
        "    - SubTree: Other\n"
        "    - KEEP_HOVERING\n", "m.yaml")
    assert document.main == "MainTree"
    go, speak, condition, land, subtree, hover = document.root.children
    assert go.ports == {"COORDINATES": "{P}", "SPEED": "1.50"}
    assert speak.ports == {"TEXT": "hello, world", "WORDS": "a, 'b, c', {K}"}
    assert (condition.type, condition.ports) == ("Condition", {"belief": "battery(self, low)"})
    assert (land.type, land.name, land.ports) == ("LAND", "down", {})
    assert (subtree.type, subtree.name, subtree.ports) == ("SubTree", "Other", {"ID": "Other"})
    assert (hover.type, hover.ports, hover.line) == ("KEEP_HOVERING", {}, 8)


def test_xml_explicit_ids_and_special_attributes():
    document = read_mission_tree(
        '<root BTCPP_format="4">\n'
        ' <BehaviorTree ID="only">\n'
        '  <Sequence>\n'
        '   <Condition ID="IsAirborne" name="up?"/>\n'
        '   <Condition belief="flight_state(self, flying)" _while="true"/>\n'
        '   <Decorator ID="Inverter"><AlwaysFailure/></Decorator>\n'
        '   <LAND _skipIf="flight_state(self, landed)" _onSuccess="done := true"/>\n'
        '  </Sequence>\n'
        ' </BehaviorTree>\n'
        '</root>\n', "m.xml")
    assert document.main == "only"
    airborne, belief, inverter, land = document.root.children
    assert (airborne.type, airborne.name, airborne.ports) == ("IsAirborne", "up?", {})
    assert belief.ports == {"belief": "flight_state(self, flying)", "_while": "true"}
    assert (inverter.type, inverter.children[0].type) == ("Inverter", "AlwaysFailure")
    assert land.ports == {"_skipIf": "flight_state(self, landed)", "_onSuccess": "done := true"}


# -- includes and subtrees -------------------------------------------------------------------------
def test_include_is_relative_to_the_including_file_and_subtrees_keep_their_remapping():
    document = load_mission_tree(DATA / "with_include.xml")
    assert set(document.trees) == {"Mission", "Land"} and document.main == "Mission"
    subtree = document.root.children[1]
    assert (subtree.type, subtree.name, subtree.line) == ("SubTree", "land there", 7)
    assert subtree.ports == {"ID": "Land", "pad": "{target}", "_autoremap": "true"}
    go = document.trees["Land"].children[0]
    assert Path(go.file) == DATA / "sub" / "landing.xml" and go.line == 4
    assert go.ports == {"COORDINATES": "{pad}", "_skipIf": "flight_state(self, landed)"}


def test_include_cycle_is_reported_where_it_closes():
    with pytest.raises(TreeFormatError) as caught:
        load_mission_tree(DATA / "cycle_a.xml")
    [(file, line, message)] = caught.value.problems
    assert (Path(file).name, line) == ("cycle_b.xml", 3)
    assert message == "include cycle: cycle_a.xml -> cycle_b.xml -> cycle_a.xml"


def test_missing_include_is_reported_on_its_line():
    with pytest.raises(TreeFormatError) as caught:
        load_mission_tree(DATA / "missing_include.xml")
    [(file, line, message)] = caught.value.problems
    assert (Path(file).name, line) == ("missing_include.xml", 4)
    assert message.startswith("included file not found:") and message.endswith("no_such_file.xml")


# -- Aerostack's format ------------------------------------------------------------------------------
def test_a_mission_in_aerostacks_format_loads():
    document = load_mission_tree(DATA / "aerostack_tower_inspection.yaml")
    root = document.root
    assert (root.type, root.name, root.line) == ("Sequence", "Tower inspection", 6)
    assert [child.type for child in root.children] == ["TAKE_OFF", "Sequence", "FOLLOW_PATH", "Sequence", "LAND"]
    south, west = root.children[1], root.children[3]
    assert [c.type for c in south.children] == ["FOLLOW_PATH", "ROTATE"]
    assert south.children[0].ports == {"PATH": "[[8, 2, 3]]"}
    assert south.children[0].name == "“Stand off the south face”"
    assert south.children[1].ports == {"ANGLE": "90"}
    assert root.children[2].ports == {"PATH": "[[2, 2, 3], [2, 8, 3]]"}
    assert west.children[0].ports == {"RELATIVE_ANGLE": "-90", "_wait_for_completion": "false"}
    assert west.children[0].line == 59


def test_aerostack_variables_become_blackboard_references():
    document = read_mission_tree(
        "nodes:\n"
        "  - {node: 1, name: m, type: control_flow, subtype: sequence, parent: 0}\n"
        "  - {node: 2, name: q, type: execution, subtype: query_belief, parent: 1,\n"
        "     parameters: 'position(?R,(?X,?Y,?Z))'}\n"
        "  - {node: 3, name: go, type: execution, subtype: task, task: FOLLOW_PATH, parent: 1,\n"
        "     parameters: 'path: [[+X,+Y,+Z]]', wait_for_completion: false}\n"
        "  - {node: 4, name: at, type: execution, subtype: task, task: go_to_point, parent: 1,\n"
        "     parameters: \"coordinates: +P\"}\n", "vars.yaml")
    query, go, at = document.root.children
    assert query.ports == {"belief": "position(?R,(?X,?Y,?Z))"}
    assert go.ports == {"PATH": "[[{X}, {Y}, {Z}]]", "_wait_for_completion": "false"}
    assert (at.type, at.ports, at.line) == ("GO_TO_POINT", {"COORDINATES": "{P}"}, 7)


# -- malformed missions: the right message on the right line, never another exception --------------
TWO_TREES = '<root BTCPP_format="4">\n<BehaviorTree ID="a"><LAND/></BehaviorTree>\n' \
            '<BehaviorTree ID="b"><LAND/></BehaviorTree>\n</root>'

MALFORMED = [
    ("not XML", "m.xml", "<root>\n<BehaviorTree ID='a'>\n<LAND>\n</root>", 4, "not well-formed XML: mismatched tag"),
    ("plain text", "m.xml", "take off, then land\n", 1, "not well-formed XML: syntax error"),
    ("empty file", "m.xml", "", 1, "not well-formed XML: no element found"),
    ("external entity", "m.xml",
     '<?xml version="1.0"?>\n<!DOCTYPE root [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>\n<root>&xxe;</root>',
     2, "DOCTYPE declaration (<!DOCTYPE root ...>) is not allowed"),
    ("undeclared entity", "m.xml", "<root>\n<BehaviorTree ID='a'>&xxe;</BehaviorTree></root>", 2,
     "undefined entity"),
    ("BTCPP_format 3", "m.xml", '\n<root BTCPP_format="3">\n<BehaviorTree ID="a"><LAND/></BehaviorTree></root>',
     2, 'BTCPP_format="3" is not supported'),
    ("two trees, no main", "m.xml", TWO_TREES, 1, "main_tree_to_execute is missing and there are 2 trees (a, b)"),
    ("unknown main", "m.xml", TWO_TREES.replace('4">', '4" main_tree_to_execute="aa">', 1), 1,
     "main_tree_to_execute names aa, but no BehaviorTree has that ID (did you mean a?)"),
    ("empty BehaviorTree", "m.xml", '<root BTCPP_format="4">\n\n<BehaviorTree ID="a">\n</BehaviorTree>\n</root>',
     3, "BehaviorTree a must have exactly one child node: it is empty"),
    ("two roots in a tree", "m.xml", '<root>\n<BehaviorTree ID="a">\n<LAND/><LAND/></BehaviorTree></root>', 2,
     "it has 2 (put them under a Sequence)"),
    ("duplicate tree IDs", "m.xml", TWO_TREES.replace('"b"', '"a"'), 3,
     "BehaviorTree a is declared twice (first at m.xml:2)"),
    ("Action without ID", "m.xml", '<root>\n<BehaviorTree ID="a">\n<Action COORDINATES="1"/></BehaviorTree></root>',
     3, 'an Action needs ID="..."'),
    ("Condition without belief", "m.xml", '<root>\n<BehaviorTree ID="a">\n<Condition/></BehaviorTree></root>', 3,
     "a Condition needs belief="),
    ("not a root element", "m.xml", "<mission>\n</mission>", 1, "the document element must be <root"),
    ("stray element", "m.xml", '<root>\n<BehaviorTree ID="a"><LAND/></BehaviorTree>\n<Behaviortree/></root>', 3,
     "unexpected <Behaviortree> in <root>"),
    ("bad YAML", "m.yaml", "tree:\n  Sequence:\n    - LAND: {ALTITUDE: [1, 2}\n", 3, "not valid YAML"),
    ("unknown YAML node form", "m.yaml", "tree:\n  Sequence:\n    - TAKE_OFF\n    - {LAND: {}, TAKE_OFF: {}}\n",
     4, "a child of Sequence: a tree node is written `TypeName: {ports}`"),
    ("number as a node", "m.yaml", "tree:\n  Sequence:\n    children:\n      - 42\n", 4,
     "a child of Sequence: a tree node is written"),
    ("unknown YAML form", "m.yaml", "mission:\n  - TAKE_OFF\n", 1, "not a behavior-tree mission: expected tree:"),
    ("YAML mapping as port", "m.yaml", "tree:\n  GO_TO_POINT:\n    COORDINATES: {x: 1, y: 2}\n", 3,
     "GO_TO_POINT: port COORDINATES: a mapping cannot be a port value"),
    ("YAML two trees no main", "m.yaml", "trees:\n  a: LAND\n  b: LAND\n", 1,
     "main_tree_to_execute is missing and there are 2 trees (a, b)"),
    ("YAML single value for a behavior", "m.yaml", "tree:\n  TAKE_OFF: 1.5\n", 2,
     "TAKE_OFF: give its ports as a mapping"),
    ("Aerostack unknown subtype", "m.yaml", "nodes:\n  - node: 1\n    parent: 0\n    subtype: sequense\n", 4,
     "node 1: unknown subtype sequense (did you mean sequence?)"),
    ("Aerostack unknown parent", "m.yaml",
     "nodes:\n  - {node: 1, parent: 0, subtype: sequence}\n  - {node: 2, parent: 7, subtype: task, task: LAND}\n",
     3, "node 2: its parent 7 is not in the list"),
    ("Aerostack two roots", "m.yaml",
     "nodes:\n  - {node: 1, parent: 0, subtype: sequence}\n  - {node: 2, parent: 0, subtype: sequence}\n",
     3, "nodes 1, 2 all have parent 0"),
    ("Aerostack repeater without times", "m.yaml", "nodes:\n  - {node: 1, parent: 0, subtype: repeater}\n", 2,
     "node 1: a repeater node needs times"),
    ("Aerostack type mismatch", "m.yaml",
     "nodes:\n  - {node: 1, parent: 0, type: control_flow, subtype: task, task: LAND}\n", 2,
     "node 1: subtype task is an execution node, not control_flow"),
    ("Aerostack parameters not pairs", "m.yaml",
     "nodes:\n  - node: 1\n    parent: 0\n    subtype: task\n    task: ROTATE\n    parameters: \"180\"\n", 6,
     "node 1: parameters must be `argument: value` pairs"),
    ("Aerostack bad parameters", "m.yaml",
     "nodes:\n  - node: 1\n    parent: 0\n    subtype: task\n    task: ROTATE\n    parameters: \"angle: [1\"\n",
     6, "node 1: parameters: not valid YAML"),
    ("Aerostack children of a task", "m.yaml",
     "nodes:\n  - {node: 1, parent: 0, subtype: task, task: LAND}\n"
     "  - {node: 2, parent: 1, subtype: task, task: LAND}\n",
     3, "node 2: its parent 1 is a task node; only control_flow nodes have children"),
    ("Aerostack parents in a cycle", "m.yaml",
     "nodes:\n  - {node: 1, parent: 0, subtype: sequence}\n  - {node: 2, parent: 3, subtype: sequence}\n"
     "  - {node: 3, parent: 2, subtype: sequence}\n", 3, "node 2 is not under the root: its parents form a cycle"),
    ("unknown extension", "m.csv", "{}", 0, "unknown mission file type .csv"),
]


@pytest.mark.parametrize(("file", "text", "line", "message"), [case[1:] for case in MALFORMED],
                         ids=[case[0] for case in MALFORMED])
def test_malformed_missions_are_refused_with_message_and_line(file, text, line, message):
    found = problems(text, file)
    assert any(message in m for _, _, m in found), found
    assert [(f, n) for f, n, m in found if message in m][0] == (file, line), found


def test_billion_laughs_is_refused_before_any_expansion():
    with pytest.raises(TreeFormatError) as caught:
        load_mission_tree(DATA / "billion_laughs.xml")
    [(file, line, message)] = caught.value.problems
    assert (Path(file).name, line) == ("billion_laughs.xml", 2)
    assert "<!DOCTYPE lolz ...>" in message and "entities and external references are refused" in message


def test_every_problem_is_reported_at_once():
    found = problems('<root BTCPP_format="3">\n<BehaviorTree ID="a"></BehaviorTree>\n'
                     '<BehaviorTree ID="b"><Action/></BehaviorTree>\n</root>', "m.xml")
    assert [line for _, line, _ in found] == [1, 2, 3, 1]


def test_an_unreadable_file_is_a_format_error(tmp_path):
    with pytest.raises(TreeFormatError, match="cannot read the file"):
        load_mission_tree(tmp_path / "absent.xml")
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"\xff\xfe\x00tree")
    with pytest.raises(TreeFormatError, match=r"binary.yaml:1: not UTF-8 text: byte 0xff at column 1"):
        load_mission_tree(binary)


@pytest.mark.parametrize("name", ["inspection.xml", "inspection.yaml", "inspection_aerostack.yaml"])
def test_any_truncation_is_a_format_error_or_a_mission(name):
    text = (DATA / name).read_text(encoding="utf-8")
    for end in range(0, len(text), 11):
        try:
            read_mission_tree(text[:end], name)
        except TreeFormatError as exc:
            assert exc.problems and all(isinstance(line, int) for _, line, _ in exc.problems)


def test_check_belief_is_the_portable_belief_condition_and_the_old_spelling_is_read_with_a_warning():
    from aeroexec.trees.loaders.xml_loader import read_xml
    from aeroexec.trees.verify import verify_document

    new = read_xml('<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><CheckBelief belief="p(a)"/>'
                   '<Condition ID="CheckBelief" belief="q(b)"/></Sequence></BehaviorTree></root>', "new.xml")
    assert [n.type for n in new.root.children] == ["CheckBelief", "CheckBelief"]
    assert not new.warnings
    old = read_xml('<root BTCPP_format="4"><BehaviorTree ID="M">\n<Condition belief="p(a)"/>'
                   '</BehaviorTree></root>', "old.xml")
    assert old.root.type == "Condition"
    [(file, line, message)] = old.warnings
    assert (file, line) == ("old.xml", 2) and "<Condition belief=...> is aeroexec's old spelling" in message
    assert "<CheckBelief" in message
    warnings = [p for p in verify_document(old) if p.severity == "warning"]  # verify counts it with the others
    assert [(p.line, p.message) for p in warnings] == [(2, message)]
