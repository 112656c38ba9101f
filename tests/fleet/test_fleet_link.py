"""The fleet link's guards: malformed or foreign messages are dropped, commands need the fleet's token,
shared beliefs arrive under the sender's name and expire when it falls silent."""

import json
import logging
import socket
import threading
import time

import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.engine import Engine
from aeroexec.fleet.access import Roster
from aeroexec.fleet.control import FleetCommandError, FleetOperator, command_fleet
from aeroexec.fleet.link import FleetLink
from aeroexec.fleet.node import FleetNode
from aeroexec.fleet.payloads import encode, tick
from aeroexec.fleet.refusals import Refusals
from aeroexec.fleet.table import FleetTable
from aeroexec.fleet.transport import free_endpoint, open_session
from patience import hang_guard


@pytest.fixture
def fleet():
    endpoint = free_endpoint()
    session = open_session("router", listen=[endpoint])
    other = open_session("client", connect=[endpoint])
    node = FleetNode(session, "f", "secret")
    engine = Engine(SimulatedDrone())
    link = FleetLink(node, "d1", engine, share=("object",)).join()
    yield endpoint, engine, link, other
    node.close()
    engine.stop()
    other.close()
    session.close()


def say(session, drone: str, *messages: tuple[str, dict]) -> None:
    """One period of ``drone``'s, as a peer puts it: its messages ``(topic, fields)``."""
    session.put(f"aeroexec/f/{drone}/tick", tick(drone, [[topic, fields] for topic, fields in messages]))


def settle(engine: Engine, until, wall: float = 5.0) -> bool:
    end = time.monotonic() + hang_guard(wall)
    while time.monotonic() < end:
        engine.step(0.05)
        if until():
            return True
        time.sleep(0.01)
    return False


def test_malformed_and_foreign_messages_are_dropped_and_the_engine_goes_on(fleet, caplog):
    endpoint, engine, link, other = fleet
    other.put("aeroexec/f/d2/tick", b"{not json")
    other.put("aeroexec/f/d2/tick", json.dumps({"v": 99, "drone": "d2", "said": []}).encode())
    other.put("aeroexec/f/d2/tick", tick("d3", [["beliefs", {"beliefs": ["object(box, thing)"]}]]))  # a liar
    say(other, "d2", ("telemetry", {"position": ["x", 1, 2]}))
    say(other, "d2", ("beliefs", {"beliefs": ["object(self, "]}))
    other.put("aeroexec/f/self/tick", tick("self", [["telemetry", {"position": [9, 9, 9]}]]))  # d1's self?
    other.put("aeroexec/f/d2/telemetry", encode("d2", position=[9, 9, 9]))  # not a key of the fleet's
    assert settle(engine, lambda: link.node.dropped >= 7)
    say(other, "d2", ("beliefs", {"beliefs": ["seen(self, marker_3)", "object(marker_3, aruco)",
                                              "object(self, drone)"]}))
    assert settle(engine, lambda: engine.memory.holds("object(d2, drone)"))
    assert engine.memory.holds("object(marker_3, aruco)")
    assert "a predicate the sender does not share (seen(d2, marker_3))" in caplog.text
    assert not engine.memory.holds("object(box, thing)")
    assert not engine.memory.holds("position(self, (9.0, 9.0, 9.0))")
    assert "not JSON" in caplog.text and "version 99" in caplog.text and "says it is from 'd3'" in caplog.text
    assert "not a key of the fleet's" in caplog.text
    assert not engine.stopped


def test_a_silent_drones_beliefs_expire_and_it_is_reported(fleet):
    endpoint, engine, link, other = fleet
    table = link.node.table  # d2 flies in another process: its silence is timed on the wall clock (shortened here)
    table.persistence, table.silent_after = 1.5, 0.75
    told = []  # what watches the memory (rules, safety monitors, the event log) hears of d2's position
    engine.memory.subscribe(lambda change: told.append((change.kind, str(change.belief)))
                            if change.belief.name == "position" else None)
    say(other, "d2", ("telemetry", {"position": [1, 2, 3], "velocity": [0.52, -1.04, 0]}),
        ("beliefs", {"beliefs": ["object(marker_5, aruco)"]}), ("broadcast", {"text": "on my way"}))
    assert settle(engine, lambda: engine.memory.holds("object(marker_5, aruco)")
                  and engine.memory.holds("position(d2, (1.0, 2.0, 3.0))")
                  and engine.memory.holds('message(d2, "on my way")'))
    assert engine.memory.holds("velocity(d2, (0.5, -1.0, 0.0))")
    assert ("added", "position(d2, (1.0, 2.0, 3.0))") in told
    said = time.monotonic()
    while time.monotonic() < said + 2.0:  # d2 keeps talking longer than its message lasts: the message stays
        say(other, "d2", ("telemetry", {"position": [1, 2, 3], "velocity": [0.52, -1.04, 0]}))
        time.sleep(0.05)
        engine.step(0.05)
    assert engine.memory.holds('message(d2, "on my way")') and engine.memory.holds("position(d2, ?P)")
    assert not engine.log.events(kind="fleet_drone_silent") and not link.silent
    assert settle(engine, lambda: link.silent == {"d2"})
    assert len(engine.log.events(kind="fleet_drone_silent")) == 1
    assert settle(engine, lambda: not engine.memory.holds('message(d2, "on my way")'))
    assert not engine.memory.holds("object(marker_5, aruco)") and not engine.memory.holds("position(d2, ?P)")
    assert not engine.memory.holds("said(d2, ?B)") and not engine.memory.holds("velocity(d2, ?V)")
    assert settle(engine, lambda: told[-1] == ("removed", "position(d2, (1.0, 2.0, 3.0))"))  # told at the next tick


def test_messages_need_social_communication(fleet):
    endpoint, engine, link, other = fleet
    say(other, "d2", ("broadcast", {"text": "area clear"}))
    assert settle(engine, lambda: engine.memory.holds('message(d2, "area clear")'))
    engine.resources.release("fleet link", engine.now())
    engine.step(3.0)  # the capability stops when nobody uses it
    assert "SOCIAL_COMMUNICATION" not in engine.resources.running()
    say(other, "d2", ("broadcast", {"text": "second"}))
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


def test_an_operator_closed_leaves_no_thread_of_its_own_behind_even_with_a_path_still_opening(fleet):
    """A command answered through one path while the other is still opening (its router slow to shake hands: here
    a listener that never speaks) and while a query still runs (an answerer that holds it): closing the operator
    waits for that path to give up and ends the query with its session, so no thread of the operator is inside
    Zenoh when the process exits (one was, ended there by the interpreter's finalization: ctl aborted after its
    answer with "FATAL: exception not rethrown")."""
    endpoint, engine, link, other = fleet
    engine.start()
    held = []  # the queries that reached the holder, never answered: each runs until its session closes
    holder = link.node.session.declare_queryable("aeroexec/f/d9/command", held.append)
    with socket.create_server(("127.0.0.1", 0)) as silent:  # connections queue in its backlog, never answered
        silent_endpoint = f"tcp/127.0.0.1:{silent.getsockname()[1]}"
        with FleetOperator([endpoint, silent_endpoint], "f", "secret", members=["d1"]) as operator:
            answers = operator.command("status")
            assert answers["d1"]["ok"] and "d9" not in answers
            assert operator.opening(), "the silent path was still opening when the command was answered"
    assert held, "the command reached the holder: its query was still running when the operator closed"
    assert [t.name for t in threading.enumerate() if t.name.startswith("aeroexec-ctl")] == []
    held.clear()
    holder.undeclare()


def test_a_drone_shares_what_it_knows_itself_never_what_others_told_it(fleet):
    endpoint, engine, link, other = fleet
    link.share = ("object", "position")
    said = []
    sub = other.declare_subscriber("aeroexec/f/d1/tick", lambda sample: said.extend(
        fields for topic, fields in json.loads(bytes(sample.payload))["said"] if topic == "beliefs"))
    time.sleep(0.3)
    engine.memory.add("object(red_box, box)")
    say(other, "d2", ("telemetry", {"position": [1, 2, 3]}), ("beliefs", {"beliefs": ["object(marker_5, aruco)"]}))
    assert settle(engine, lambda: engine.memory.holds("object(marker_5, aruco)") and len(said) >= 2)
    engine.step(1.1)
    assert settle(engine, lambda: len(said) >= 3)
    sub.undeclare()
    last = said[-1]["beliefs"]
    assert "object(red_box, box)" in last and any(b.startswith("position(self, (") for b in last)
    assert not any("marker_5" in b or "d2" in b for b in last)


def test_a_peers_beliefs_keep_their_source_and_never_replace_what_the_drone_knows_itself(fleet):
    endpoint, engine, link, other = fleet
    link.share = ("object", "code", "position", "charge")  # what this drone accepts from peers (no roster here)
    engine.memory.add("code(marker_3, 3)")  # seen by this drone's own camera
    say(other, "d2", ("beliefs", {"beliefs": [
        "code(marker_3, 4)", "object(marker_5, aruco)", "position(self, (1, 2, 3))", "charge(battery, 5)",
        "position(d1, (9, 9, 9))", "object(d1, enemy)", "said(d3, object(x, y))", "color(marker_5, red)"]}))
    assert settle(engine, lambda: engine.memory.holds("object(marker_5, aruco)"))
    memory = engine.memory
    assert memory.holds("said(d2, object(marker_5, aruco))") and memory.holds("position(d2, (1.0, 2.0, 3.0))")
    assert memory.query_all("said(?D, object(marker_5, ?C))") == [{"?D": "d2", "?C": "aruco"}]
    assert memory.holds("code(marker_3, 3)") and not memory.holds("code(marker_3, 4)")  # its own stays
    assert memory.holds("said(d2, code(marker_3, 4))")  # the claim is kept apart, with its source
    assert not memory.holds("charge(battery, 5)") and not memory.holds("position(d1, (9.0, 9.0, 9.0))")
    assert not memory.holds("object(d1, enemy)") and not memory.holds("said(d3, ?X)")
    refused = {e.data["reason"]: e.detail for e in engine.log.events(kind="fleet_refused")}
    assert set(refused) == {"contradicts what this drone believes itself (kept as said)",
                            "about this drone's own state", "about this drone",
                            "reports what others said (only a drone's own claims are heard)",
                            "a predicate the sender does not share"}
    assert refused["about this drone's own state"] == "from d2: about this drone's own state (charge(battery, 5))"
    for _ in range(3):  # said again and again: refused again, but each reason is one event
        say(other, "d2", ("beliefs", {"beliefs": ["charge(battery, 5)"]}))
        settle(engine, lambda: False, wall=0.2)
    assert len(engine.log.events(kind="fleet_refused")) == 5


def test_refusals_are_counted_not_repeated(fleet, caplog):
    endpoint, engine, link, other = fleet
    for _ in range(5000):
        other.put("aeroexec/f/d9/tick", b"{not json")
    assert settle(engine, lambda: link.node.dropped >= 1000)
    time.sleep(0.5)
    link.node.close()
    lines = [r.getMessage() for r in caplog.records if "refused" in r.getMessage()]
    assert len(lines) == 2, lines
    assert lines[0].startswith("fleet f: refused a message from d9: not JSON (not JSON on aeroexec/f/d9/tick")
    counted = int(lines[1].split("refused ")[1].split(" more")[0].replace(",", ""))
    assert lines[1].startswith(f"fleet f: refused {counted:,} more messages from d9 in the last ")
    assert counted + 1 == link.node.dropped >= 1000
    assert [e.detail.split(" (")[0] for e in engine.log.events(kind="fleet_refused")] == ["from d9: not JSON"]


def test_a_count_is_logged_once_per_interval():
    clock = [0.0]
    refusals = Refusals("f", interval=10.0, clock=lambda: clock[0])
    lines = []
    handler = logging.Handler()
    handler.emit = lambda record: lines.append(record.getMessage())
    logging.getLogger("aeroexec.fleet.refusals").addHandler(handler)
    try:
        assert refusals.refuse("ghost", "not a fleet member")
        for t in (1.0, 2.0, 3.0):
            clock[0] = t
            assert not refusals.refuse("ghost", "not a fleet member")
            refusals.flush()
        clock[0] = 10.5
        refusals.flush()
        refusals.flush()
        clock[0] = 30.0
        refusals.flush(final=True)
    finally:
        logging.getLogger("aeroexec.fleet.refusals").removeHandler(handler)
    assert lines == ["fleet f: refused a message from ghost: not a fleet member; more of the same are counted, one "
                     "line every 10 s",
                     "fleet f: refused 3 more messages from ghost in the last 10 s: not a fleet member"]


@pytest.mark.parametrize("given", ["the fleet file's trust:", "run --fleet --trust code=2"])
def test_a_trusted_predicate_is_believed_only_while_enough_distinct_members_say_it(given):
    """trust: {code: 2}: one member's code(...) is held as said(d2, ...) only; a second member saying it makes the
    drone believe it, with both sources; when one of them stops saying it, the belief goes. The same for a drone
    in its own process (no fleet file: its own --trust)."""
    endpoint = free_endpoint()
    session = open_session("router", listen=[endpoint])
    others = {d: open_session("client", connect=[endpoint]) for d in ("d2", "d3")}
    roster = Roster("f", {f"{d}@f": (d,) for d in ("d1", "d2", "d3", "d4")},
                    shares={d: ("object", "code") for d in ("d1", "d2", "d3", "d4")}, trust={"code": 2})
    from_file = given.startswith("the fleet file")
    node = FleetNode(session, "f", "secret", roster if from_file else None, local=("d1",))
    engine = Engine(SimulatedDrone())
    FleetLink(node, "d1", engine, share=("object", "code"), trust=None if from_file else {"code": 2}).join()
    memory = engine.memory
    try:
        def d2_says() -> bool:
            say(others["d2"], "d2", ("beliefs", {"beliefs": ["code(marker_77, 3)", "object(marker_77, aruco)"]}))
            return memory.holds("said(d2, code(marker_77, 3))") and memory.holds("object(marker_77, aruco)")

        assert settle(engine, d2_says, wall=30)
        assert not memory.holds("code(marker_77, 3)")  # one member is not enough
        assert memory.holds("object(marker_77, aruco)")  # a predicate the fleet does not guard: believed
        claims = engine.log.events(kind="fleet_claim")
        assert [c.detail for c in claims] == [
            "from d2: code(marker_77, 3) (said by 1 of the 2 members needed to believe it)"]

        def both_say() -> bool:
            d2_says()
            say(others["d3"], "d3", ("beliefs", {"beliefs": ["code(marker_77, 3)"]}))
            return memory.holds("code(marker_77, 3)")

        assert settle(engine, both_say, wall=30)
        assert memory.query_all("said(?D, code(marker_77, 3))") == [{"?D": "d2"}, {"?D": "d3"}]
        believed = [e.detail for e in engine.log.events(kind="fleet_belief") if "code" in e.detail]
        assert believed == ["from d2, d3: code(marker_77, 3)"]
        # d3 falls silent: what it said expires, and with one member left the belief goes (d2 still says it)
        assert settle(engine, lambda: d2_says() and not memory.holds("said(d3, code(marker_77, 3))"), wall=60)
        assert not memory.holds("code(marker_77, 3)") and memory.holds("said(d2, code(marker_77, 3))")
    finally:
        node.close()
        engine.stop()
        for other in others.values():
            other.close()
        session.close()


@pytest.mark.parametrize("word", ["code", "code=0", "code=two", "Code(x)=2", "=2", "code=²"])
def test_a_wrong_trust_argument_is_a_usage_error_naming_it(tmp_path, capsys, word):
    from aeroexec.cli.main import main

    (tmp_path / "m.py").write_text("def mission():\n    pass\n")
    status = main(["run", str(tmp_path / "m.py"), "--fleet", "f", "--name", "d1", "--trust", word, "--output",
                   str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert f"--trust {word}: give PREDICATE=K" in err and "Traceback" not in err


def test_an_operator_keeps_trying_to_reach_a_router_on_another_machine_and_once_on_the_loopback():
    """Over a lossy network one TLS handshake can fail: the operator's client session tries again for 15 s (the
    network test's `ctl` once answered "cannot open the fleet link" while the router was there); on the loopback
    a missing router is said at once, and routers and drones keep Zenoh's own connecting rules."""
    from aeroexec.fleet.transport import NETWORK_CONNECT_MS, config

    remote = config("client", connect=["tcp/10.77.0.1:7447"])
    assert json.loads(remote.get_json("connect/timeout_ms")) == NETWORK_CONNECT_MS == 15000
    assert json.loads(remote.get_json("connect/retry"))["period_init_ms"] == 250
    for session in (config("client", connect=["tcp/127.0.0.1:7447"]), config("peer", connect=["tcp/10.77.0.1:7447"])):
        assert json.loads(session.get_json("connect/timeout_ms")) is None


def test_a_link_whose_close_times_out_is_a_warning_not_an_error(caplog):
    """ctl has its answers when it closes its link; Zenoh's "close operation timed out" (a router cut off or slow)
    once made the command an internal error (exit 70) in the network test."""
    from aeroexec.fleet.transport import close_session

    class Stuck:
        def close(self):
            raise RuntimeError("close operation timed out!")

    with caplog.at_level(logging.WARNING):
        close_session(Stuck())
    assert "the fleet link did not close cleanly: close operation timed out!" in caplog.text


@pytest.mark.parametrize(("position", "where"), [
    ([1.5, -2.0, 3.0], (1.5, -2.0, 3.0)), ([1, 2, 3], (1.0, 2.0, 3.0)), ([float("nan"), 0.0, 0.0], None),
    ([1.0, float("-inf"), 0.0], None), ([True, 0.0, 0.0], None), ([1.0, 2.0], None), ([10**400, 0.0, 0.0], None),
    ("1, 2, 3", None)], ids=["floats", "integers", "NaN", "infinity", "a boolean", "two", "too large", "text"])
def test_a_mate_is_where_its_telemetry_says_only_when_that_is_three_finite_numbers(position, where):
    refused = []
    table = FleetTable(lambda sender, reason, example, what: refused.append(reason))
    news = table.take([("d2", "telemetry", {"position": position, "velocity": [0.0, 0.0, 0.0]})], 1.0)
    assert table.where.get("d2") == where and news.came == ([("d2", where)] if where else [])
    assert refused == ([] if where else ["telemetry: not 3 numbers"])


def test_a_drone_nobody_listened_to_is_heard_by_a_listener_that_comes_mid_flight(fleet):
    """A tick nobody outside the process listens to is not made; one that comes is heard from then on."""
    endpoint, engine, link, other = fleet
    for _ in range(10):  # nobody listens: no tick is made
        engine.step(0.05)
    heard, came = [], threading.Event()
    listener = other.declare_subscriber("aeroexec/f/d1/tick", lambda sample: (
        heard.append(json.loads(bytes(sample.payload))), came.set()))
    try:
        assert settle(engine, came.is_set)
    finally:
        listener.undeclare()
    assert heard[0]["drone"] == "d1" and [topic for topic, _ in heard[0]["said"]]
