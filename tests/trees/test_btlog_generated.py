"""Generated trees (hypothesis): the transitions our .btlog writer logs for our runtime's ticks are BehaviorTree.CPP's
own for the same tree, its leaves scripted alike (RUNNING, SUCCESS, FAILURE, tick after tick), halts included.

The nodes: Sequence, Fallback, ReactiveSequence, ReactiveFallback, Parallel, IfThenElse, Inverter, ForceSuccess,
ForceFailure and SubTree. (SequenceWithMemory, WhileDoElse, Repeat and RetryUntilSuccessful tick differently in
our runtime and in BehaviorTree.CPP 4.8 today, so the logs differ there by what was ticked, not by how it is
logged: the parity suite of the runtime is where they are compared.)"""

from __future__ import annotations

import gc
import itertools
from types import SimpleNamespace

import behaviortreepy as bt
import pytest
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees.groot.btlog import TransitionTracker, read_btlog
from aeroexec.trees.loaders.xml_writer import write_xml
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.builder import TreeBuilder, describe
from aeroexec.trees.runtime.ticking import TickState, attach, result_name, status_name, tick_tree
from btcpp_files import settle
from depth import examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from py_trees.behaviour import Behaviour
from py_trees.common import Status

CONTROLS = ("Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback", "Parallel")
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure")
TICKS = 6
COUNT = itertools.count()
STATUSES = {"R": Status.RUNNING, "S": Status.SUCCESS, "F": Status.FAILURE}
BT_STATUS = {"R": "RUNNING", "S": "SUCCESS", "F": "FAILURE"}


class Scripted(Behaviour):
    """A leaf returning, at tick k, the k-th letter of its script (R, S or F)."""

    def __init__(self, name: str, script: str, clock: list[int]) -> None:
        super().__init__(name)
        self.script, self.clock = script, clock

    def update(self) -> Status:
        return STATUSES[self.script[self.clock[0]]]


class ScriptedBuilder(TreeBuilder):
    """The scripted leaves registered as a leaf type of the caller's."""

    def __init__(self, document: TreeDocument, clock: list[int]) -> None:
        context = SimpleNamespace(engine=SimpleNamespace(catalog=default_catalog()), now=lambda: 0.0)
        leaves = {"Scripted": lambda model, board: Scripted(model.name, model.ports["_script"], clock)}
        super().__init__(document, context, leaves)  # type: ignore[arg-type]


def _subtree(child: TreeNode) -> TreeNode:
    node = TreeNode("SubTree", "SubTree", {"ID": ""}, [], named=False)
    node.inner = child  # type: ignore[attr-defined]
    return node


def trees(depth: int) -> st.SearchStrategy[TreeNode]:
    leaf = st.text("RSF", min_size=TICKS, max_size=TICKS).map(
        lambda script: TreeNode("Scripted", "leaf", {"_script": script}))
    if depth == 0:
        return leaf
    inner = trees(depth - 1)
    return st.one_of(
        leaf,
        st.builds(lambda kind, children: TreeNode(kind, kind, {}, children), st.sampled_from(CONTROLS),
                  st.lists(inner, min_size=1, max_size=3)),
        st.builds(lambda kind, child: TreeNode(kind, kind, {}, [child]), st.sampled_from(DECORATORS), inner),
        st.builds(_subtree, inner),
        st.builds(lambda children: TreeNode("IfThenElse", "IfThenElse", {}, children),
                  st.lists(inner, min_size=3, max_size=3)),  # without an else, a failed condition is never reset
        # in BT.CPP 4.8, and a stateful action ticked again then answers its old status without being called
    )


def document_of(root: TreeNode) -> TreeDocument:
    """Each SubTree gets a tree of its own (``Inner1``, ``Inner2``...), and each leaf a unique name."""
    trees: dict[str, TreeNode] = {"Main": root}
    count = [0, 0]

    def visit(node: TreeNode) -> None:
        if node.type == "Scripted":
            count[1] += 1
            node.name = f"leaf{count[1]}"
        if node.type == "SubTree":
            count[0] += 1
            node.ports["ID"] = f"Inner{count[0]}"
            trees[node.ports["ID"]] = node.inner  # type: ignore[attr-defined]
            visit(node.inner)  # type: ignore[attr-defined]
        for child in node.children:
            visit(child)

    visit(root)
    return TreeDocument(trees, "Main", "generated.xml")


def ours(document: TreeDocument) -> list[tuple[int, str]]:
    clock = [0]
    root = ScriptedBuilder(document, clock).build(Blackboard())
    mission = SimpleNamespace(nodes=describe(root), root=root)
    found: list[tuple[int, str]] = []
    tracker = TransitionTracker(mission, lambda uid, status: found.append((uid, status)))
    attach(root, TickState())
    for clock[0] in range(TICKS):
        tracker.ticked([(node, result_name(result)) for node, result in tick_tree(root)])  # as the runner does
        if status_name(root) != "RUNNING":
            return found
    root.stop(Status.INVALID)
    tracker.halted()
    return found


def theirs(document: TreeDocument, scripts: dict[str, str], path) -> list[tuple[int, str]]:
    clock = [0]

    def status(node: bt.TreeNode) -> str:
        return BT_STATUS[scripts[node.name()][clock[0]]]

    factory = bt.BehaviorTreeFactory()
    factory.register_simple_stateful_action("Scripted", status, status, lambda node: None)
    tree = factory.create_tree_from_text(write_xml(document))  # BT.CPP passes the _script attributes over
    logger = bt.FileLogger(tree, str(path))
    header = path.stat().st_size
    for clock[0] in range(TICKS):
        if tree.tick_exactly_once() != bt.NodeStatus.RUNNING:
            break
    else:
        tree.halt_tree()
    settle(path, header)  # FileLogger2 writes from its thread every 10 ms; closing drops what is still queued
    del logger, tree
    gc.collect()
    return [(t.uid, t.status_name) for t in read_btlog(path).transitions]


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
@settings(max_examples=examples(70), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(root=st.builds(lambda kind, children: TreeNode(kind, kind, {}, children), st.sampled_from(CONTROLS),
                      st.lists(trees(2), min_size=1, max_size=3)))  # (BT.CPP 4.8 logs nothing under a root SubTree)
def test_generated_trees_log_btcpps_transitions(root, tmp_path):
    document = document_of(root)
    scripts = {n.name: n.ports["_script"] for tree in document.trees.values() for n in tree.walk()
               if n.type == "Scripted"}
    path = tmp_path / f"theirs{next(COUNT)}.btlog"  # a file of its own: an old logger may still be closing
    assert ours(document) == theirs(document, scripts, path)
