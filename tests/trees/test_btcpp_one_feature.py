"""The one-feature trees (``one_feature_trees``) run in BehaviorTree.CPP (behaviortreepy, 4.8.2; the reference is 4.10,
whose changes each case records in ``since_4_10``) and in aeroexec:
every tick of every node, every halt, the blackboard and where a run stops on an error (refused at load, thrown at a
tick) are the same; BT.CPP's own lenient-XML test trees run; and the set holds a tree for every built-in node and
every port BT.CPP declares on it.
"""

from __future__ import annotations

import re

import pytest
from aeroexec.trees.groot import palette as groot
from aeroexec.trees.runtime.manifests import MANIFESTS
from btcpp_harness import compare, run_aeroexec
from one_feature_trees import DATA, LENIENT, ONE_FEATURE, Case
from test_btcpp_parity import HAND_WRITTEN, SUBTREES

S, F, R = "SUCCESS", "FAILURE", "RUNNING"
ENGINE_LEAVES = (*groot.ENGINE_LEAVES, "Condition")  # aeroexec's own leaves: BT.CPP has none of them
#: TryCatch came with BT.CPP 4.10, which behaviortreepy does not embed: its trees are checked against the ticks
#: read off 4.10's try_catch_node.cpp (test_btcpp_parity has the tick tables).
ONLY_4_10 = {
    "TryCatch catch_on_halt": '<TryCatch catch_on_halt="true"><A/><B/></TryCatch>',
}


def tree(case: Case) -> str:
    main = '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">'
    return main + case.body + "</BehaviorTree>" + "".join(case.subtrees) + "</root>"


@pytest.mark.parametrize("name", sorted(ONE_FEATURE))
def test_one_feature_tree_runs_as_in_btcpp(name, tmp_path):
    case = ONE_FEATURE[name]
    compare(tree(case), case.scripts, case.ticks, tmp_path, case.between, case.blackboard, case.since_4_10)


@pytest.mark.parametrize("name", sorted(LENIENT))
def test_btcpp_test_trees_with_raw_lt_or_ampersands_in_attributes_run_as_in_btcpp(name, tmp_path):
    scripts, blackboard = LENIENT[name]
    theirs, _ = compare((DATA / name).read_text(), scripts, 6, tmp_path, blackboard=blackboard)
    assert theirs.error_at is None and len(theirs.roots) == 6  # BT.CPP runs it


def test_the_loop_of_the_issue_ends_after_the_three_items_of_its_text():
    run = run_aeroexec(tree(ONE_FEATURE["LoopInt queue from SetBlackboard text"]), {"A": [S]}, 4,
                       blackboard={"sum": 0})
    assert run.roots == [R, R, R, S] and run.blackboard["sum"] == "6"


def test_the_set_has_a_tree_for_every_built_in_node_and_every_port():
    texts = [tree(c) for c in ONE_FEATURE.values()] + [body + "".join(SUBTREES.get(name, []))
                                                       for name, (body, _) in HAND_WRITTEN.items()]
    texts += [(DATA / name).read_text() for name in LENIENT] + list(ONLY_4_10.values())
    written = " ".join(texts)
    count = len(ONE_FEATURE) + len(HAND_WRITTEN) + len(LENIENT) + len(ONLY_4_10)
    assert count >= 113
    missing = []
    for name, manifest in MANIFESTS.items():
        if name in ENGINE_LEAVES:
            continue
        if not re.search(rf"<{name}[\s/>]", written):
            missing.append(name)
        missing += [f"{name}.{port.name}" for port in manifest.ports
                    if not re.search(rf"<{name}\b[^>]*\s{port.name}=", written)]
    assert missing == []
