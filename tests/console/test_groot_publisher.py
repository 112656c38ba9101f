"""aeroexec's Groot2 publisher answers as BehaviorTree.CPP's own Groot2Publisher does (behaviortreepy runs the
real one on the same tree), and btview, a Groot2 monitor nobody here wrote, shows our nodes with their statuses."""

import json
import os
import re
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree

import behaviortreepy as bt
import msgpack
import pytest
import zmq
from aeroexec.trees.groot.publisher import GrootPublisher, GrootPublisherError
from console_helpers import TREE, free_port

REQUEST_ID = 0x11223344


def request(port, kind, payload=None, raw=None):
    context = zmq.Context.instance()
    sock = context.socket(zmq.REQ)
    sock.setsockopt(zmq.RCVTIMEO, 3000)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(f"tcp://127.0.0.1:{port}")
    try:
        frames = raw if raw is not None else [struct.pack("<BBI", 2, ord(kind), REQUEST_ID)] + (
            [payload] if payload is not None else [])
        sock.send_multipart(frames)
        return sock.recv_multipart()
    finally:
        sock.close()


def statuses(buffer):
    return {struct.unpack_from("<H", buffer, i)[0]: buffer[i + 2] for i in range(0, len(buffer), 3)}


def tree_shape(xml):
    """(tag, name, uid) of every node with a uid, and the BehaviorTree instances' ids and paths."""
    root = ElementTree.fromstring(xml)
    nodes = [(e.tag, e.get("name"), int(e.get("_uid"))) for e in root.iter() if e.get("_uid")]
    trees = [(e.get("ID"), e.get("_fullpath")) for e in root.iter("BehaviorTree")]
    return nodes, trees


@pytest.fixture
def btcpp():
    """BehaviorTree.CPP's own Groot2Publisher on the same tree, its leaves scripted to succeed."""
    factory = bt.BehaviorTreeFactory()
    for name in ("TAKE_OFF", "LAND"):
        factory.register_simple_stateful_action(name, lambda n: "RUNNING", lambda n: "SUCCESS", lambda n: None)
    tree = factory.create_tree_from_text(TREE)
    port = free_port(2)
    publisher = bt.Groot2Publisher(tree, port)
    yield tree, port
    del publisher


@pytest.fixture
def ours(tree_mission):
    port = free_port(2)
    publisher = GrootPublisher(tree_mission, port=port)
    yield tree_mission, port
    publisher.close()


def test_every_request_type_is_answered_with_the_structure_btcpp_answers_it(ours, btcpp):
    mission, port = ours
    tree, their_port = btcpp
    mission.start()
    mission.engine.step(0.5)  # TAKE_OFF running
    tree.tick_exactly_once()  # TAKE_OFF running there too
    for kind, payload in [("T", None), ("S", None), ("B", b"Main"), ("r", b"start"), ("t", None), ("r", b"stop"),
                          ("D", None), ("A", None), ("X", None)]:
        mine, theirs = request(port, kind, payload), request(their_port, kind, payload)
        assert len(mine) == len(theirs), kind
        assert len(mine[0]) == len(theirs[0]) == 22 and mine[0][:6] == theirs[0][:6], kind  # header echoed + uuid
    assert tree_shape(request(port, "T")[1]) == tree_shape(request(their_port, "T")[1])
    mine, theirs = statuses(request(port, "S")[1]), statuses(request(their_port, "S")[1])
    assert mine.keys() == theirs.keys()
    running = {uid for uid, s in mine.items() if s == 1}
    assert running == {uid for uid, s in theirs.items() if s == 1} == {1, 2}  # the sequence and TAKE_OFF
    assert set(msgpack.unpackb(request(port, "B", b"Main;nope")[1])) == set(
        msgpack.unpackb(request(their_port, "B", b"Main;nope")[1])) == {"Main"}
    assert json.loads(request(port, "D")[1]) == json.loads(request(their_port, "D")[1]) == []
    for raw in ([b"\x02T"], [struct.pack("<BBI", 2, ord("Z"), 1)], [struct.pack("<BBI", 2, ord("B"), 1)]):
        mine, theirs = request(port, None, raw=raw), request(their_port, None, raw=raw)
        assert mine[0] == theirs[0] == b"error"
        assert mine[1] == theirs[1]  # the same message text


def test_recorded_transitions_come_as_9_byte_records_and_idle_remembers_the_last_status(ours):
    mission, port = ours
    assert request(port, "r", b"start")[1].isdigit()
    mission.run(max_time=60)
    records = request(port, "t")[1]
    assert records and len(records) % 9 == 0
    decoded = [(int.from_bytes(records[i:i + 6], "little"), *struct.unpack_from("<HB", records, i + 6))
               for i in range(0, len(records), 9)]
    assert [t for t, _, _ in decoded] == sorted(t for t, _, _ in decoded)
    assert (2, 2) in [(uid, s) for _, uid, s in decoded]  # TAKE_OFF succeeded
    assert request(port, "t")[1] == b""  # drained on read
    final = statuses(request(port, "S")[1])
    assert final[1] == 2  # the sequence ended SUCCESS and is reported so


def test_breakpoints_are_refused_in_words(ours):
    _, port = ours
    reply = request(port, "I", json.dumps({"enabled": True, "uid": 2, "mode": 0, "once": False,
                                            "desired_status": "SUCCESS", "position": 0}).encode())
    assert reply[0] == b"error" and b"not supported" in reply[1]


def test_a_taken_port_is_a_clear_error(tree_mission, ours):
    _, port = ours
    with pytest.raises(GrootPublisherError, match=f"ports {port} and {port + 1}"):
        GrootPublisher(tree_mission, port=port)


def test_btview_attaches_to_a_running_mission_and_names_our_nodes_with_their_statuses(tmp_path):
    port = free_port(2)
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    run = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "run", "missions/figure10.xml", "--plain",
                            "--groot", str(port), "--speed", "1", "--output", str(tmp_path / "out")],
                           cwd=os.path.dirname(os.path.dirname(os.path.dirname(__file__))),
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    try:
        deadline = time.monotonic() + 30
        for line in run.stderr:
            if "Groot2: connect" in line or time.monotonic() > deadline:
                break
        time.sleep(2.5)  # the mission is flying
        btview = os.path.join(os.path.dirname(sys.executable), "btview")  # installed beside this Python
        view = subprocess.run([btview, "snapshot", "--ascii", "--no-color", "--uid", "-p", str(port),
                               "--timeout", "5"], capture_output=True, text=True, timeout=30)
    finally:
        run.terminate()
        run.wait(timeout=30)
    assert view.returncode == 0, view.stderr
    assert "TAKE_OFF" in view.stdout and "GO_TO_POINT" in view.stdout
    assert re.search(r"RUNNING|SUCCESS", view.stdout), view.stdout
