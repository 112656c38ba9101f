"""The fleet link's guards: malformed or foreign messages are dropped, commands need the fleet's token,
shared beliefs arrive under the sender's name and expire when it falls silent."""

import json
import time

import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.engine import Engine
from aeroexec.fleet.control import FleetCommandError, command_fleet
from aeroexec.fleet.link import FleetLink
from aeroexec.fleet.node import FleetNode
from aeroexec.fleet.payloads import encode
from aeroexec.fleet.transport import free_endpoint, open_session


@pytest.fixture
def fleet():
    endpoint = free_endpoint()
    session = open_session("router", listen=[endpoint])
    other = open_session("client", connect=[endpoint])
    node = FleetNode(session, "f", "secret")
    engine = Engine(SimulatedDrone())
    link = FleetLink(node, "d1", engine, share=("object",), persistence=1.0).join()
    yield endpoint, engine, link, other
    node.close()
    engine.stop()
    other.close()
    session.close()


def settle(engine: Engine, until, wall: float = 5.0) -> bool:
    end = time.monotonic() + wall
    while time.monotonic() < end:
        engine.step(0.05)
        if until():
            return True
        time.sleep(0.01)
    return False


def test_malformed_and_foreign_messages_are_dropped_and_the_engine_goes_on(fleet, caplog):
    endpoint, engine, link, other = fleet
    other.put("aeroexec/f/d2/beliefs", b"{not json")
    other.put("aeroexec/f/d2/beliefs", json.dumps({"v": 99, "drone": "d2", "beliefs": []}).encode())
    other.put("aeroexec/f/d2/beliefs", encode("d3", beliefs=["object(box, thing)"]))  # lies about its sender
    other.put("aeroexec/f/d2/telemetry", encode("d2", position=["x", 1, 2]))
    other.put("aeroexec/f/d2/beliefs", encode("d2", beliefs=["object(self, "]))
    other.put("aeroexec/f/self/telemetry", encode("self", position=[9, 9, 9]))  # would pass for this drone
    assert settle(engine, lambda: link.node.dropped >= 6)
    other.put("aeroexec/f/d2/beliefs", encode("d2", beliefs=["seen(self, marker_3)", "object(marker_3, aruco)",
                                                             "object(self, drone)"]))
    assert settle(engine, lambda: engine.memory.holds("object(d2, drone)"))
    assert engine.memory.holds("object(marker_3, aruco)")
    assert "a predicate the sender does not share (seen(d2, marker_3))" in caplog.text
    assert not engine.memory.holds("object(box, thing)")
    assert not engine.memory.holds("position(self, (9.0, 9.0, 9.0))")
    assert "not JSON" in caplog.text and "version 99" in caplog.text and "says it is from 'd3'" in caplog.text
    assert not engine.stopped


def test_a_silent_drones_beliefs_expire_and_it_is_reported(fleet):
    endpoint, engine, link, other = fleet
    other.put("aeroexec/f/d2/telemetry", encode("d2", sent=time.time(), position=[1, 2, 3]))
    other.put("aeroexec/f/d2/beliefs", encode("d2", beliefs=["object(marker_5, aruco)"]))
    other.put("aeroexec/f/d2/broadcast", encode("d2", text="on my way"))
    assert settle(engine, lambda: engine.memory.holds("object(marker_5, aruco)")
                  and engine.memory.holds("position(d2, (1.0, 2.0, 3.0))")
                  and engine.memory.holds('message(d2, "on my way")'))
    for _ in range(12):  # d2 keeps talking: its message stays though its persistence (1 s) has passed
        other.put("aeroexec/f/d2/telemetry", encode("d2", sent=time.time(), position=[1, 2, 3]))
        settle(engine, lambda: False, wall=0.1)
    assert engine.memory.holds('message(d2, "on my way")')
    assert not engine.log.events(kind="fleet_drone_silent")
    assert settle(engine, lambda: engine.log.events(kind="fleet_drone_silent"), wall=4.0)
    assert link.silent == {"d2"}
    assert settle(engine, lambda: not engine.memory.holds('message(d2, "on my way")'), wall=2.0)
    assert not engine.memory.holds("object(marker_5, aruco)") and not engine.memory.holds("position(d2, ?P)")


def test_messages_need_social_communication(fleet):
    endpoint, engine, link, other = fleet
    other.put("aeroexec/f/d2/broadcast", encode("d2", text="area clear"))
    assert settle(engine, lambda: engine.memory.holds('message(d2, "area clear")'))
    engine.resources.release("fleet link", engine.now())
    engine.step(3.0)  # the capability stops when nobody uses it
    assert "SOCIAL_COMMUNICATION" not in engine.resources.running()
    other.put("aeroexec/f/d2/broadcast", encode("d2", text="second"))
    time.sleep(0.3)
    engine.step(0.2)
    assert not engine.memory.holds('message(d2, "second")')


def test_commands_need_the_fleets_token(fleet):
    endpoint, engine, link, other = fleet
    engine.start()
    with pytest.raises(FleetCommandError, match="wrong token"):
        command_fleet([endpoint], "f", "guess", "abort")
    assert engine.supervisor.state == "running"
    answers = command_fleet([endpoint], "f", "secret", "status")
    assert answers["d1"]["ok"] and "position" in answers["d1"]["status"]
    answers = command_fleet([endpoint], "f", "secret", "pause", drone="d1")
    assert answers["d1"]["ok"] and engine.supervisor.state == "paused"


def test_a_drone_shares_what_it_knows_itself_never_what_others_told_it(fleet):
    endpoint, engine, link, other = fleet
    link.share = ("object", "position")
    said = []
    sub = other.declare_subscriber("aeroexec/f/d1/beliefs",
                                   lambda sample: said.append(json.loads(bytes(sample.payload))))
    time.sleep(0.3)
    engine.memory.add("object(red_box, box)")
    other.put("aeroexec/f/d2/telemetry", encode("d2", sent=time.time(), position=[1, 2, 3]))
    other.put("aeroexec/f/d2/beliefs", encode("d2", beliefs=["object(marker_5, aruco)"]))
    assert settle(engine, lambda: engine.memory.holds("object(marker_5, aruco)") and len(said) >= 2)
    engine.step(1.1)
    assert settle(engine, lambda: len(said) >= 3)
    sub.undeclare()
    last = said[-1]["beliefs"]
    assert "object(red_box, box)" in last and any(b.startswith("position(self, (") for b in last)
    assert not any("marker_5" in b or "d2" in b for b in last)
