"""Every XML tree aeroexec accepts in missions/ and tests/**/data loads and ticks in BehaviorTree.CPP itself.

BT.CPP (behaviortreepy) gets our palette (``aeroexec groot-model``) registered: every catalog behavior and engine
leaf as a node answering SUCCESS (CheckBelief as a condition). behaviortreepy 0.1.4 cannot declare ports from
Python (BT.CPP then refuses any attribute on those nodes), so what is compared is split in two: this test checks
each attribute of a palette node against the ports the palette declares for it (what BT.CPP would check with
the palette registered in C++), then removes those attributes and lets BT.CPP load the rest -- tags, structure,
its own built-in nodes with all their ports, scripts, SubTree remapping, includes -- and tick the tree to its end.
The blackboard starts with the variables the tree's QueryBelief nodes would bind, as they would in flight.
Missions must also pass ``verify --strict-btcpp``.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import behaviortreepy as bt
import pytest
from aeroexec.cli.main import main
from aeroexec.dialects.aerostack2.tree_nodes import is_aerostack2
from aeroexec.dialects.tml.compiler import load_xml_mission
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees.groot.palette import palette_ports
from aeroexec.trees.loaders.lenient_xml import escape_attributes
from aeroexec.trees.mission_file import load_mission_tree
from aeroexec.trees.model import TreeFormatError
from aeroexec.trees.portability import portability_problems
from aeroexec.trees.verify import verify_document

ROOT = Path(__file__).resolve().parents[2]
MISSIONS = sorted(p for p in (ROOT / "missions").glob("*.xml") if not p.name.endswith(".tml.xml"))
DATA = sorted(p for p in (ROOT / "tests").glob("**/data/**/*.xml") if not p.name.endswith(".tml.xml"))
CATALOG = default_catalog()
PALETTE = palette_ports(CATALOG)
CONDITIONS = {"CheckBelief"}


def accepted(path: Path) -> bool:
    try:
        if is_aerostack2(load_xml_mission(path)):
            return False  # BehaviorTree.CPP 3 files for Aerostack2's plugins (tests/aerostack fly them)
        document = load_mission_tree(path)
    except TreeFormatError:
        return False
    return not [p for p in verify_document(document, CATALOG) if p.severity == "error"]


def for_btcpp(path: Path, folder: Path, variables: set[str]) -> Path:
    """The file with the palette nodes' ports checked against the palette and removed (and its includes so)."""
    text, _ = escape_attributes(path.read_bytes(), str(path))  # ElementTree reads strict XML: tinyxml2 reads more
    tree = ElementTree.ElementTree(ElementTree.fromstring(text))
    for element in tree.iter():
        if element.tag == "include":
            target = path.parent / element.get("path", "")
            element.set("path", str(for_btcpp(target, folder, variables)))
            continue
        kind = element.get("ID") if element.tag in ("Action", "Condition") and element.get("ID") else element.tag
        if kind == "QueryBelief":
            variables.update(re.findall(r"\?([A-Za-z_]\w*)", element.get("belief", "")))
        if kind not in PALETTE or element.tag == "TreeNodesModel":
            continue
        for port in list(element.attrib):
            if port in ("name", "ID") or port.startswith("_"):
                continue
            assert port in PALETTE[kind], f"{path}: the port {port} of {kind} is not in the palette"
            del element.attrib[port]
    for model in tree.getroot().findall("TreeNodesModel"):  # our own palette is what is registered, with the
        for node in [n for n in model if n.tag != "SubTree"]:  # file's SubTree models (their ports' defaults)
            model.remove(node)
        if not len(model):
            tree.getroot().remove(model)
    out = folder / f"{path.parent.name}_{path.name}"
    tree.write(out)
    return out


def factory() -> bt.BehaviorTreeFactory:
    made = bt.BehaviorTreeFactory()
    for kind in PALETTE:
        if kind in CONDITIONS:
            made.register_simple_condition(kind, lambda node: "SUCCESS")
        else:
            made.register_simple_action(kind, lambda node: "SUCCESS")
    return made


ACCEPTED = [p for p in MISSIONS + DATA if accepted(p)]  # the others test aeroexec's refusals


def test_the_portability_check_covers_every_mission_and_some_test_data():
    assert set(MISSIONS) <= set(ACCEPTED) and set(ACCEPTED) - set(MISSIONS)


@pytest.mark.parametrize("path", ACCEPTED, ids=lambda p: str(p.relative_to(ROOT)))
def test_accepted_xml_trees_load_and_tick_in_btcpp(path, tmp_path):
    variables: set[str] = set()
    converted = for_btcpp(path, tmp_path, variables)
    board = bt.Blackboard.create()
    for name in variables:
        board.set_double(name, 1.0)
    tree = factory().create_tree_from_file(str(converted), board)
    status = tree.tick_exactly_once()  # raises when BT.CPP cannot tick it (a script, a port it cannot read)
    for _ in range(30):
        if status != bt.NodeStatus.RUNNING:
            break
        status = tree.tick_exactly_once()
    if path in MISSIONS:  # every palette leaf succeeds: a mission runs to its end
        assert status == bt.NodeStatus.SUCCESS


@pytest.mark.parametrize("path", MISSIONS, ids=lambda p: p.name)
def test_missions_are_portable(path, capsys):
    assert portability_problems(load_mission_tree(path), CATALOG) == []
    assert main(["verify", "--strict-btcpp", str(path)]) == 0


def test_strict_btcpp_flags_every_non_portable_construct(tmp_path, capsys):
    mission = tmp_path / "old.xml"
    mission.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>\n'
        '<TAKE_OFF/>\n'
        '<Condition belief="flight_state(self, flying)"/>\n'
        '<QueryBelief belief="position(self, (?x, ?y, ?z))"/>\n'
        '<GO_TO_POINT COORDINATES="{x}, {y}, 3" _skipIf="flight_state(self, landed)"/>\n'
        '<ScriptCondition code=\'belief("flight_state(self, flying)")\'/>\n'
        '<GO_TO_POINT coordinates="1, 1, 1"/>\n'
        '<LAND/></Sequence></BehaviorTree></root>')
    assert main(["verify", str(mission)]) == 0
    capsys.readouterr()
    assert main(["verify", "--strict-btcpp", str(mission)]) == 1
    out = capsys.readouterr().out
    assert f"{mission}:3: error: NOT_PORTABLE: <Condition belief=...> is refused by BehaviorTree.CPP" in out
    assert f"{mission}:5: error: NOT_PORTABLE: COORDINATES=\"{{x}}, {{y}}, 3\": {{key}} inside a longer value" in out
    assert f"{mission}:5: error: NOT_PORTABLE: _skipIf=\"flight_state(self, landed)\" is a belief expression" in out
    assert f"{mission}:6: error: NOT_PORTABLE: code=" in out and "uses belief(" in out
    assert f"{mission}:7: error: NOT_PORTABLE: the port coordinates of GO_TO_POINT is not in the palette" in out
    assert out.count("NOT_PORTABLE") == 5


NAMES = ROOT / "tests" / "trees" / "data" / "btcpp_tests" / "name_validation"  # BT.CPP 4.10's tests (SOURCES.md)


@pytest.mark.parametrize("path", sorted(NAMES.glob("*.xml")), ids=lambda p: p.stem)
def test_strict_btcpp_refuses_the_names_btcpp_4_10_refuses_with_its_reason(path):
    document = load_mission_tree(path)
    assert not [p for p in verify_document(document, CATALOG) if p.severity == "error"]  # aeroexec reads it
    problems = portability_problems(document, CATALOG)
    if path.stem.startswith("Invalid"):  # BT.CPP 4.10's test expects createTreeFromText to throw
        reason = {"Root": "'Root' is a reserved name and cannot be used as a node type",
                  "root_lowercase": "'Root' is a reserved name", "WithSpace": "contains forbidden character ' '",
                  "WithPeriod": "contains forbidden character '.'", "Reserved": "is a reserved attribute name",
                  "StartsWithDigit": "cannot start with a digit"}[path.stem.split("_", 1)[1]]
        assert problems and all(reason in p.message and p.line > 0 for p in problems)
    else:
        assert problems == []


def test_strict_btcpp_refuses_a_tree_named_after_a_node_type(tmp_path):
    mission = tmp_path / "named.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="TAKE_OFF">\n<BehaviorTree ID="TAKE_OFF">'
                       '<SubTree ID="Sequence"/></BehaviorTree>\n<BehaviorTree ID="Sequence"><AlwaysSuccess/>'
                       '</BehaviorTree></root>')
    problems = [(p.line, p.message) for p in portability_problems(load_mission_tree(mission), CATALOG)]
    assert problems == [
        (2, "The attribute [ID] of tag <BehaviorTree> must not use the name of a registered Node (TAKE_OFF)"),
        (3, "The attribute [ID] of tag <BehaviorTree> must not use the name of a registered Node (Sequence)"),
        (2, "The attribute [ID] of tag <SubTree> must not use the name of a registered Node (Sequence)")]


def test_strict_btcpp_refuses_what_btcpp_4_10_refuses_in_models_and_ids_as_written(tmp_path, capsys):
    """xml_parsing.cpp of 4.10: loadSubtreeModel throws on a model <SubTree> without ID, VerifyXML on a second
    <TreeNodesModel>, and validateModelName checks an ID as written (not stripped: " S" holds a space)."""
    mission = tmp_path / "models.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M">\n'
                       '<BehaviorTree ID="M"><Sequence><SubTree ID=" S"/><SubTree ID="S"/></Sequence></BehaviorTree>\n'
                       '<BehaviorTree ID="S"><AlwaysSuccess/></BehaviorTree>\n'
                       '<TreeNodesModel><SubTree><input_port name="x"/></SubTree></TreeNodesModel>\n'
                       '<TreeNodesModel/>\n</root>')
    assert main(["verify", str(mission)]) == 0  # aeroexec reads it, with warnings
    capsys.readouterr()
    assert main(["verify", "--strict-btcpp", str(mission)]) == 1
    out = capsys.readouterr().out
    assert f"{mission}:2: error: NOT_PORTABLE: Model name ' S' contains forbidden character ' '" in out
    assert f"{mission}:4: error: NOT_PORTABLE: Missing attribute 'ID' in SubTree element within TreeNodesModel" in out
    assert f"{mission}:5: error: NOT_PORTABLE: Only a single node <TreeNodesModel> is supported" in out
    assert out.count("NOT_PORTABLE") == 3


def test_an_undefined_entity_is_read_as_its_text_with_a_warning_and_lines_stay_right(tmp_path, capsys):
    mission = tmp_path / "entity.xml"  # strict XML refused &y;, tinyxml2 keeps it; a raw newline stays one
    mission.write_text('<root BTCPP_format="4">\n<BehaviorTree ID="M"><Sequence><Script code="x := 1;\ny := 2"/>\n'
                       '<Script code="s := \'a&y;b\'"/>\n<Bogus/></Sequence></BehaviorTree></root>\n')
    assert main(["verify", str(mission)]) == 1
    out = capsys.readouterr().out
    assert f"{mission}:4: warning: WRONG_FORMAT: an attribute holds an undefined entity (read as its text)" in out
    assert f"{mission}:5: error: WRONG_FORMAT: The behavior Bogus does not exist" in out


def test_raw_lt_and_ampersands_in_attributes_are_read_with_a_warning_and_flagged_by_strict_btcpp(tmp_path, capsys):
    mission = tmp_path / "raw.xml"
    mission.write_text('<root BTCPP_format="4">\n<BehaviorTree ID="M"><Sequence><Script code="value := 10"/>\n'
                       '<AlwaysSuccess _skipIf="value < 25 &amp;&amp; value > 5"/>\n'
                       '<ScriptCondition code="value >= 10 && value != 3"/></Sequence></BehaviorTree></root>')
    assert main(["verify", str(mission)]) == 0
    out = capsys.readouterr().out
    assert f"{mission}:3: warning: WRONG_FORMAT: an attribute holds a raw '<', which is not well-formed XML" in out
    assert f"{mission}:4: warning: WRONG_FORMAT: an attribute holds a raw '&'" in out and "&amp;&amp; for &&" in out
    assert out.count(": warning: ") == 2 and out.rstrip().endswith("0 errors, 2 warnings; ready to fly (checked "
                                                                     "against the world default field)")
    assert main(["verify", "--strict-btcpp", str(mission)]) == 1
    out = capsys.readouterr().out
    assert out.count("error: NOT_PORTABLE: an attribute holds a raw") == 2
