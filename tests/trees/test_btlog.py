"""The FileLogger2 (.btlog) layout: transitions as BehaviorTree.CPP's bit fields, and a reader that refuses what
does not follow the format."""

import struct

import pytest
from aeroexec.trees.btlog import BtlogError, decode_transition, encode_transition, read_btlog

XML = '<root BTCPP_format="4"><BehaviorTree ID="T" _fullpath=""><Sequence name="s" _uid="1">' \
      '<LAND name="LAND" _uid="2"/></Sequence></BehaviorTree><TreeNodesModel/></root>'


def btlog(xml: str = XML, transitions: bytes = b"") -> bytes:
    data = xml.encode()
    return struct.pack("<i", len(data)) + data + struct.pack("<q", 1_700_000_000_000_000) + transitions


def test_a_transition_is_45_bits_of_microseconds_16_of_uid_and_3_of_status():
    assert encode_transition(1, 2, 3) == struct.pack("<Q", 1 | 2 << 45 | 3 << 61)
    usec = (1 << 45) - 1
    assert decode_transition(encode_transition(usec, 65535, 4)) == decode_transition(
        struct.pack("<Q", usec | 65535 << 45 | 4 << 61))
    assert decode_transition(encode_transition(123456, 7, 2)).status_name == "SUCCESS"
    with pytest.raises(ValueError):
        encode_transition(1 << 45, 1, 1)


def test_the_reader_reads_the_header_and_the_transitions(tmp_path):
    path = tmp_path / "t.btlog"
    path.write_bytes(btlog(transitions=encode_transition(0, 1, 1) + encode_transition(500, 2, 3) + b"\x01\x02"))
    log = read_btlog(path)
    assert log.first_timestamp_usec == 1_700_000_000_000_000 and log.nodes() == {1: ("Sequence", "s"),
                                                                               2: ("LAND", "LAND")}
    assert [(t.usec, t.uid, t.status_name) for t in log.transitions] == [(0, 1, "RUNNING"), (500, 2, "FAILURE")]


@pytest.mark.parametrize("data, message", [
    (b"\x01", "too short"),
    (struct.pack("<i", 999) + b"<root/>", "does not fit"),
    (btlog("<root><oops></root>"), "does not parse"),
    (btlog(transitions=encode_transition(0, 9, 1)), "uid 9"),
    (btlog(transitions=encode_transition(0, 1, 6)), "status 6"),
])
def test_the_reader_refuses_what_is_not_the_format(tmp_path, data, message):
    path = tmp_path / "bad.btlog"
    path.write_bytes(data)
    with pytest.raises(BtlogError, match=message):
        read_btlog(path)
