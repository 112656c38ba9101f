"""The FileLogger2 (.btlog) layout of BehaviorTree.CPP 4.3 and later: 9-byte records after a header, and a reader
that refuses what does not follow the format."""

import struct
from pathlib import Path

import pytest
from aeroexec.trees.groot.btlog import MAGIC, BtlogError, decode_transition, encode_transition, read_btlog
from aeroexec.trees.mission_file import read_mission_tree
from aeroexec.trees.verify import verify_document

XML = '<root BTCPP_format="4"><BehaviorTree ID="T" _fullpath=""><Sequence name="s" _uid="1">' \
      '<LAND name="LAND" _uid="2"/></Sequence></BehaviorTree><TreeNodesModel/></root>'


def btlog(xml: str = XML, transitions: bytes = b"", protocol: int = 1) -> bytes:
    data = xml.encode()
    return MAGIC + bytes([protocol]) + struct.pack("<i", len(data)) + data + \
        struct.pack("<q", 1_700_000_000_000_000) + transitions


def test_a_transition_is_6_bytes_of_microseconds_a_16_bit_uid_and_a_status_byte():
    assert encode_transition(0x0102030405, 0x0a0b, 3) == bytes([5, 4, 3, 2, 1, 0, 0x0b, 0x0a, 3])
    usec = (1 << 48) - 1
    assert decode_transition(encode_transition(usec, 65535, 4)) == decode_transition(b"\xff" * 8 + b"\x04")
    assert decode_transition(encode_transition(123456, 7, 2)).status_name == "SUCCESS"
    with pytest.raises(ValueError):
        encode_transition(1 << 48, 1, 1)


def test_the_reader_reads_the_header_and_the_transitions(tmp_path):
    path = tmp_path / "t.btlog"
    path.write_bytes(btlog(transitions=encode_transition(0, 1, 1) + encode_transition(500, 2, 3)))
    log = read_btlog(path)
    assert log.first_timestamp_usec == 1_700_000_000_000_000 and log.nodes() == {1: ("Sequence", "s"),
                                                                               2: ("LAND", "LAND")}
    assert [(t.usec, t.uid, t.status_name) for t in log.transitions] == [(0, 1, "RUNNING"), (500, 2, "FAILURE")]
    assert log.subtrees() == [("T", "")]


def test_a_file_of_behaviortree_cpp_4_2_is_refused_with_a_clear_message(tmp_path):
    old = struct.pack("<i", len(XML)) + XML.encode() + struct.pack("<q", 1) + struct.pack("<Q", 1 << 45)
    path = tmp_path / "old.btlog"
    path.write_bytes(old)  # BT.CPP 4.2's layout: no header, 8-byte records
    with pytest.raises(BtlogError, match="does not start with BTCPP4-FileLogger2"):
        read_btlog(path)


@pytest.mark.parametrize("data, message", [
    (MAGIC + b"\x01\x01", "too short"),
    (btlog(protocol=2), "protocol 2"),
    (MAGIC + b"\x01" + struct.pack("<i", 999) + b"<root/>", "does not fit"),
    (btlog("<root><oops></root>"), "does not parse"),
    (btlog(transitions=encode_transition(0, 9, 1)), "uid 9"),
    (btlog(transitions=encode_transition(0, 1, 6)), "status 6"),
    (btlog(transitions=encode_transition(0, 1, 1) + b"\x01\x02"), "whole number"),
])
def test_the_reader_refuses_what_is_not_the_format(tmp_path, data, message):
    path = tmp_path / "bad.btlog"
    path.write_bytes(data)
    with pytest.raises(BtlogError, match=message):
        read_btlog(path)


def test_the_reader_reads_a_file_behaviortree_cpp_4_8_wrote():
    """data/btcpp_4_8_2.btlog: behaviortreepy's FileLogger, one tick of Sequence(IsReady, SubTree Fly(Fallback(
    AlwaysFailure, Step)))."""
    log = read_btlog(Path(__file__).parent / "data" / "btcpp_4_8_2.btlog")
    assert log.subtrees() == [("Main", ""), ("Fly", "fly")]
    assert log.nodes()[3] == ("SubTree", "fly") and log.nodes()[5] == ("AlwaysFailure", "nope")
    assert [(t.uid, t.status_name) for t in log.transitions][:6] == [
        (1, "RUNNING"), (2, "SUCCESS"), (3, "RUNNING"), (4, "RUNNING"), (5, "FAILURE"), (6, "RUNNING")]
    assert [(t.uid, t.status_name) for t in log.transitions][-2:] == [(1, "SUCCESS"), (1, "IDLE")]


def test_two_subtrees_with_one_path_are_refused_as_behaviortree_cpp_4_10_refuses_them():
    xml = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Fly" name="leg"/>
      <SubTree ID="Fly"/>
      <SubTree ID="Fly"/>
      <SubTree ID="Fly" name="leg"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Fly"><LAND/></BehaviorTree>
</root>"""
    problems = verify_document(read_mission_tree(xml, "dup.xml"))
    duplicates = [p for p in problems if "Duplicate SubTree path" in p.message]
    assert [(p.line, p.severity) for p in duplicates] == [(7, "error")]  # unnamed ones get ID::uid, unique
    assert "'leg'" in duplicates[0].message
