"""Our ``.btlog`` against BehaviorTree.CPP's own FileLogger2 (behaviortreepy embeds BehaviorTree.CPP 4.8.2): a tree
mission flown on the simulator and the same tree ticked by BehaviorTree.CPP, its leaves scripted to return what ours
returned tick after tick, give the same file but for timestamps and the node palette; one reader reads both."""

from __future__ import annotations

import gc
import struct
from pathlib import Path

import behaviortreepy as bt
import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.trees.groot.btlog import MAGIC, RECORD, BtlogWriter, read_btlog
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.runtime.runner import TreeMission
from btcpp_files import settle
from py_trees.common import Status

MISSION = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="mission">
      <TAKE_OFF/>
      <SubTree ID="Photo" name="photo"/>
      <SubTree ID="Photo"/>
      <Fallback>
        <AlwaysFailure name="nope"/>
        <Inverter><AlwaysFailure/></Inverter>
      </Fallback>
      <Parallel success_count="1">
        <TAKE_PHOTO name="last photo"/>
        <KEEP_HOVERING/>
      </Parallel>
      <RetryUntilSuccessful num_attempts="2">
        <SubTree ID="Land" name="Land"/>
      </RetryUntilSuccessful>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Photo">
    <Sequence><TAKE_PHOTO/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Land">
    <Sequence>
      <SubTree ID="Photo"/>
      <ReactiveSequence>
        <AlwaysSuccess name="ok &amp; &quot;safe&quot;"/>
        <LAND/>
      </ReactiveSequence>
    </Sequence>
  </BehaviorTree>
</root>
"""
LEAVES = ("TAKE_OFF", "TAKE_PHOTO", "KEEP_HOVERING", "LAND")


def sections(data: bytes) -> tuple[bytes, str, list[bytes]]:
    """The header before the XML, the XML, and the records without their timestamps."""
    (size,) = struct.unpack_from("<i", data, len(MAGIC) + 1)
    start = len(MAGIC) + 5
    body = data[start + size + 8:]
    return data[:start], data[start:start + size].decode(), [body[i + 6:i + RECORD] for i in range(0, len(body),
                                                                                                    RECORD)]


@pytest.fixture(scope="module")
def ours(tmp_path_factory) -> tuple[Path, list[dict[int, str]]]:
    """Our run on the simulator, its .btlog, and every leaf's status after each tick (uid -> status)."""
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    try:
        mission = TreeMission(read_xml(MISSION, "parity.xml"), engine)
        path = tmp_path_factory.mktemp("btlog") / "ours.btlog"
        writer = BtlogWriter(mission, path, engine.catalog)
        leaves = {uid: node for uid, (_, node) in enumerate(mission.nodes, 1) if node.source.type in LEAVES}
        ticks: list[dict[int, str]] = []
        mission.observers.append(lambda visited: ticks.append(
            {uid: status for uid, node in leaves.items() for v, status in visited or () if v is node}))
        assert mission.run(300.0) == Status.SUCCESS
        writer.close()
    finally:
        engine.stop()
    return path, ticks


@pytest.fixture(scope="module")
def theirs(ours, tmp_path_factory) -> Path:
    """BehaviorTree.CPP's FileLogger2 on the same tree, the leaves replaying our statuses tick by tick."""
    _, ticks = ours
    now = [0]

    def scripted(node: bt.TreeNode) -> str:
        return ticks[now[0]][node.uid()]

    factory = bt.BehaviorTreeFactory()
    for leaf in LEAVES:
        factory.register_simple_stateful_action(leaf, scripted, scripted, lambda node: None)
    tree = factory.create_tree_from_text(MISSION)
    path = tmp_path_factory.mktemp("btlog") / "theirs.btlog"
    logger = bt.FileLogger(tree, str(path))
    header = path.stat().st_size
    for now[0] in range(len(ticks)):
        status = tree.tick_exactly_once()
    assert status == bt.NodeStatus.SUCCESS
    settle(path, header)
    del logger, tree
    gc.collect()
    return path


def test_the_header_and_the_trees_xml_are_byte_for_byte_btcpps(ours, theirs):
    our_header, our_xml, _ = sections(ours[0].read_bytes())
    their_header, their_xml, _ = sections(theirs.read_bytes())
    assert our_header[:len(MAGIC) + 1] == their_header[:len(MAGIC) + 1] == MAGIC + b"\x01"
    cut = "    <TreeNodesModel>"
    assert our_xml[:our_xml.index(cut)] == their_xml[:their_xml.index(cut)]
    assert our_xml.endswith("</TreeNodesModel>\n</root>\n") and their_xml.endswith("</TreeNodesModel>\n</root>\n")


def test_subtree_paths_are_btcpps_unnamed_ones_with_their_uid(ours, theirs):
    expected = [("Main", ""), ("Photo", "photo"), ("Photo", "Photo::6"), ("Land", "Land"),
                ("Photo", "Land/Photo::19")]
    assert read_btlog(ours[0]).subtrees() == read_btlog(theirs).subtrees() == expected
    assert read_btlog(ours[0]).nodes()[17] == ("SubTree", "Land::17")  # named as its ID: BT.CPP adds the uid


def test_the_transitions_are_btcpps_but_for_their_timestamps(ours, theirs):
    _, _, our_records = sections(ours[0].read_bytes())
    _, _, their_records = sections(theirs.read_bytes())
    assert len(our_records) > 40
    assert our_records == their_records


def test_one_reader_reads_both_files(ours, theirs):
    mine, bts = read_btlog(ours[0]), read_btlog(theirs)
    assert mine.nodes() == bts.nodes()
    assert [(t.uid, t.status_name) for t in mine.transitions] == [(t.uid, t.status_name) for t in bts.transitions]
    assert mine.transitions[-1].status_name == "IDLE" and mine.transitions[-2].status_name == "SUCCESS"
    times = [t.usec for t in mine.transitions]
    assert times == sorted(times) and times[-1] > 3_000_000  # engine time: the flight took seconds


HALTED = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <TAKE_OFF/>
      <ReactiveSequence>
        <AlwaysSuccess/>
        <Parallel success_count="2" failure_count="2">
          <KEEP_HOVERING/>
          <SubTree ID="Hold"/>
        </Parallel>
      </ReactiveSequence>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Hold">
    <Inverter><WAIT name="long wait" DURATION="100"/></Inverter>
  </BehaviorTree>
</root>
"""


def test_a_tree_halted_mid_flight_logs_btcpps_halt_transitions(tmp_path):
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    statuses: list[dict[int, str]] = []
    try:
        mission = TreeMission(read_xml(HALTED, "halted.xml"), engine)
        writer = BtlogWriter(mission, tmp_path / "ours.btlog", engine.catalog)
        leaves = {uid: node for uid, (_, node) in enumerate(mission.nodes, 1)
                  if node.source.type in ("TAKE_OFF", "KEEP_HOVERING", "WAIT")}
        mission.observers.append(lambda visited: statuses.append(
            {uid: status for uid, node in leaves.items() for v, status in visited or () if v is node}))
        mission.run(15.0)  # halted at the time limit, everything running
        assert mission.done and mission.root.status == Status.INVALID
        writer.close()
    finally:
        engine.stop()
    ticks = statuses[:-1]  # the last call is the halt
    now = [0]
    factory = bt.BehaviorTreeFactory()
    for leaf in ("TAKE_OFF", "KEEP_HOVERING", "WAIT"):
        factory.register_simple_stateful_action(leaf, lambda n: ticks[now[0]][n.uid()],
                                                lambda n: ticks[now[0]][n.uid()], lambda n: None)
    tree = factory.create_tree_from_text(HALTED.replace(' DURATION="100"', ""))
    logger = bt.FileLogger(tree, str(tmp_path / "theirs.btlog"))
    header = (tmp_path / "theirs.btlog").stat().st_size
    for now[0] in range(len(ticks)):
        assert tree.tick_exactly_once() == bt.NodeStatus.RUNNING
    tree.halt_tree()
    settle(tmp_path / "theirs.btlog", header)
    del logger, tree
    gc.collect()
    ours, theirs = read_btlog(tmp_path / "ours.btlog"), read_btlog(tmp_path / "theirs.btlog")
    mine = [(t.uid, t.status_name) for t in ours.transitions]
    assert mine == [(t.uid, t.status_name) for t in theirs.transitions]
    assert mine[-1] == (1, "IDLE") and ("long wait" in ours.xml)
    last = dict(mine)
    assert set(last) == set(ours.nodes()) and set(last.values()) == {"IDLE"}  # halted: every node back to IDLE
    assert mine[-8:] == [(2, "IDLE"), (6, "IDLE"), (9, "IDLE"), (8, "IDLE"), (7, "IDLE"), (5, "IDLE"), (3, "IDLE"),
                         (1, "IDLE")]  # BT.CPP halts deepest first; the ReactiveSequence's condition was IDLE
