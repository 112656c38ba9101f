"""The changes as the operator sends them: their text form (what ``aeroexec ctl`` sends, the Python API builds),
Aerostack2's mission updates mapped onto them, ``aeroexec ctl`` against a live run (from another folder: a file to
load is named by its full path), and a fleet's drone changed through ``ctl --fleet``'s Zenoh query."""

from __future__ import annotations

import io
import subprocess
import sys
import threading
import time

import pytest
from aeroexec.engine import MissionChange
from aeroexec.engine.supervision.changes import AEROSTACK2_UPDATES, ChangeError, aerostack2_update
from changing import DATA, ended
from flight_runs import Command, read_log  # tests/flight's, put on the path by changing

PATROL = DATA / "patrol.xml"


@pytest.mark.parametrize("change, command, argument", [
    (MissionChange.skip(), "skip", ""),
    (MissionChange.jump(2), "jump", "2"),
    (MissionChange.jump("corner A"), "jump", "'corner A'"),
    (MissionChange.insert(5, "GO_TO_POINT COORDINATES=\"1, 2, 3\"", after=True), "insert",
     "after 5 'GO_TO_POINT COORDINATES=\"1, 2, 3\"'"),
    (MissionChange.modify("item 7", SPEED=3, COORDINATES=(1, 2, 3)), "modify",
     "'item 7' SPEED=3 'COORDINATES=1, 2, 3'"),
    (MissionChange.delete(4), "delete", "4"),
    (MissionChange.replace("laps", "<ROTATE ANGLE=\"45\"/>"), "replace", "laps '<ROTATE ANGLE=\"45\"/>'"),
    (MissionChange.load("/tmp/a mission.plan"), "load", "'/tmp/a mission.plan'"),
])
def test_a_change_is_its_text_and_its_text_is_the_change(change, command, argument):
    assert (change.command, change.argument) == (command, argument)
    assert MissionChange.parse(command, argument) == change


@pytest.mark.parametrize("command, argument, said", [
    ("skip", "now", "skip takes no argument: it skips the item running now"),
    ("jump", "", "jump needs an argument: jump TARGET"),
    ("insert", "5 LAND", "usage: insert before|after TARGET FRAGMENT"),
    ("modify", "5 SPEED", "modify: 'SPEED' is not PORT=VALUE; usage: modify TARGET PORT=VALUE [PORT=VALUE...]"),
    ("delete", "'corner A", "delete: the argument cannot be read (No closing quotation); usage: delete TARGET"),
    ("delete", "corner A", "usage: delete TARGET (a name with spaces is quoted)"),
])
def test_a_change_that_cannot_be_read_says_how_it_is_written(command, argument, said):
    with pytest.raises(ChangeError) as error:
        MissionChange.parse(command, argument)
    assert str(error.value).startswith(said)


def test_aerostack2s_mission_updates_map_onto_the_changes():
    assert aerostack2_update("NEXT_ITEM") == ("skip", "")
    assert aerostack2_update("PAUSE") == ("pause", "") and aerostack2_update("RESUME") == ("resume", "")
    assert aerostack2_update("STOP") == ("abort", "") and aerostack2_update("ABORT") == ("abort", "")
    assert aerostack2_update("START", item_id=2) == ("jump", "3")  # Aerostack2 numbers items from 0
    assert aerostack2_update("REPEAT", item_id=5) == ("jump", "1")
    assert aerostack2_update("REMOVE", item_id=0) == ("delete", "1")
    assert aerostack2_update("INSERT", 1, fragment="<LAND/>") == ("insert", "before 2 '<LAND/>'")
    assert aerostack2_update("MODIFY", 1, fragment="SPEED=2") == ("modify", "2 SPEED=2")
    assert aerostack2_update("LOAD", mission="/m/plan.json") == ("load", "/m/plan.json")
    assert set(AEROSTACK2_UPDATES) >= {"LOAD", "START", "PAUSE", "RESUME", "STOP", "NEXT_ITEM", "REPEAT", "INSERT",
                                       "MODIFY", "REMOVE", "RESET"}
    with pytest.raises(ChangeError, match="has no meaning here"):
        aerostack2_update("TELEPORT")


def ctl(cwd, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "ctl", *args], capture_output=True, text=True,
                          timeout=60, cwd=cwd)


def test_aeroexec_ctl_changes_a_live_run_from_another_folder(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "home.xml").write_text((DATA / "patrol_home.xml").read_text())
    run = Command(tmp_path, "run", str(PATROL), "--plain", "--speed", "0.25", "--output", str(tmp_path / "out"))
    # (at a quarter of real time, corner A flies for ~12 s: time for a ctl process to start on a loaded machine;
    # at real time, ~3 s were not enough in a loaded CI: corner B was running when the pause came)
    try:
        run.wait_for("corner A: IDLE -> RUNNING")
        assert ctl(elsewhere, "pause").returncode == 0
        items = ctl(elsewhere, "items")
        assert items.returncode == 0, items.stderr
        assert "      2  running  corner A" in items.stdout and "      4  to come  laps" in items.stdout
        refused = ctl(elsewhere, "insert", "after", "2", "GO_TO_POINT COORDINATES=\"40, 0, 3\"")
        assert refused.returncode == 1 and "outside the world's bounds" in refused.stderr
        inserted = ctl(elsewhere, "insert", "after", "2", "GO_TO_POINT COORDINATES=\"9, -3, 4\" name=detour")
        assert inserted.returncode == 0 and inserted.stdout.endswith("detour inserted after corner A\n")
        assert ctl(elsewhere, "skip").returncode == 0
        loaded = ctl(elsewhere, "load", "home.xml")  # relative to ctl's folder, not the run's
        assert loaded.returncode == 0, loaded.stderr
        assert ctl(elsewhere, "resume").returncode == 0
        code, out, _ = run.finish()
    finally:
        run.process.kill()
    assert code == 0
    records = read_log(tmp_path / "out" / "events.jsonl")
    said = [(r["data"]["command"], r["data"]["ok"], r["data"]["origin"]) for r in records
            if r["kind"] == "mission_change"]
    assert said == [("insert", False, "ctl"), ("insert", True, "ctl"), ("skip", True, "ctl"), ("load", True, "ctl")]
    assert "mission_change: load " in out and ended(records) == "completed"


def test_a_fleet_drone_takes_changes_through_ctl_fleet(tmp_path):
    from aeroexec.fleet.control import command_fleet
    from aeroexec.fleet.node import FleetNode
    from aeroexec.fleet.transport import free_endpoint, open_session
    from aeroexec.flight import FleetJoin, FlightSession, FlightSpec

    endpoint = free_endpoint()
    router = open_session("router", listen=[endpoint])
    node = FleetNode(router, "f", "secret")
    spec = FlightSpec(mission=PATROL, output=str(tmp_path / "d1"), register=False, speed=4.0,
                      fleet=FleetJoin("f", "d1"))
    session = FlightSession(spec, notify=lambda text: None, fleet_node=node).open()
    flying = threading.Thread(target=session.fly, daemon=True)
    try:
        flying.start()
        deadline = time.monotonic() + 60
        while not (session.tree and any(n.name == "corner A" and n.status.name == "RUNNING"
                                        for _, n in session.tree.nodes)):
            assert time.monotonic() < deadline, "corner A never ran"
            time.sleep(0.05)
        assert command_fleet([endpoint], "f", "secret", "pause", drone="d1")["d1"]["ok"]
        items = command_fleet([endpoint], "f", "secret", "items", drone="d1")["d1"]
        assert [i["name"] for i in items["items"]] == ["take off", "corner A", "corner B", "laps", "corner C", "land"]
        refused = command_fleet([endpoint], "f", "secret", "insert", "after 2 TAKE_OFF", drone="d1")["d1"]
        assert not refused["ok"] and "WRONG_SEQUENCE" in refused["problems"][0]
        skipped = command_fleet([endpoint], "f", "secret", "skip", drone="d1")["d1"]  # what ctl --fleet sends
        assert skipped["ok"] and skipped["message"].startswith(
            "corner A (line 8) skipped; the mission goes on with corner B (line 9)"), skipped
        assert command_fleet([endpoint], "f", "secret", "abort", drone="d1")["d1"]["ok"]
        flying.join(timeout=60)
    finally:
        session.close()
        node.close()
        router.close()
    records = read_log(tmp_path / "d1" / "events.jsonl")
    assert [(r["data"]["command"], r["data"]["origin"]) for r in records if r["kind"] == "mission_change"] == [
        ("insert", "fleet"), ("skip", "fleet")]


def test_the_live_views_keys_skip_and_jump():
    from aeroexec.cli.views.live import KeyReader

    submitted = []

    class Supervisor:
        def submit(self, command: str, argument: str, origin: str):
            submitted.append((command, argument, origin))
            return type("Ticket", (), {"wait": lambda self, timeout: None})()

    keys = KeyReader(Supervisor(), stream=io.StringIO())
    for key in "n" + "jcorner A\r" + "j\r":
        keys.press(key)
    assert submitted == [("skip", "", "keyboard"), ("jump", "'corner A'", "keyboard")]


def test_aerostack2_updates_reach_a_running_mission_as_the_changes_they_mean():
    from aeroexec.engine.supervision.changes import parse_aerostack2_update

    assert parse_aerostack2_update("NEXT_ITEM") == ("skip", "")
    assert parse_aerostack2_update("INSERT 3 'GO_TO_POINT COORDINATES=\"1, 2, 3\"'") == \
        ("insert", "before 4 'GO_TO_POINT COORDINATES=\"1, 2, 3\"'")
    assert parse_aerostack2_update("modify 2 SPEED=2") == ("modify", "3 SPEED=2")
    with pytest.raises(ChangeError, match="has no meaning here"):
        parse_aerostack2_update("TELEPORT 1")


@pytest.mark.parametrize("update, said", [
    ("INSERT \u00b2 LAND", "update INSERT: '\u00b2' is not an item id (Aerostack2 numbers items 0, 1, 2... "
                           "written with the digits 0-9)"),
    ("INSERT " + "7" * 5000 + " LAND", "update INSERT: '777777777777777777777777'... (5000 characters) is not an "
                                      "item id"),
    ("REMOVE -1", "update REMOVE: '-1' is not an item id"),
    ("INSERT", "update INSERT: the fragment to insert is missing (update INSERT [ITEM_ID] FRAGMENT"),
    ("INSERT 2", "update INSERT: the fragment to insert is missing"),
    ("MODIFY 2", "update MODIFY: the new values are missing (update MODIFY ITEM_ID PORT=VALUE..."),
    ("LOAD", "update LOAD: the mission file to load is missing (update LOAD FILE)"),
])
def test_an_aerostack2_update_with_a_bad_item_id_or_nothing_to_insert_is_refused_naming_it(update, said):
    from aeroexec.engine.supervision.changes import parse_aerostack2_update

    with pytest.raises(ChangeError) as error:
        parse_aerostack2_update(update)
    assert str(error.value).startswith(said), error.value


@pytest.mark.parametrize("command, argument, said", [
    ("insert", "before 3 ''", "insert: the fragment to insert is missing; usage: insert before|after TARGET FRAGMENT"),
    ("replace", "3 '  '", "replace: the fragment to put in its place is missing; usage: replace TARGET FRAGMENT"),
])
def test_an_insert_or_replace_with_an_empty_fragment_is_refused(command, argument, said):
    with pytest.raises(ChangeError) as error:
        MissionChange.parse(command, argument)
    assert str(error.value) == said


def test_a_target_that_is_no_item_number_is_refused_naming_it_and_the_mission_flies_on(tmp_path):
    from changing import ChangedFlight

    flight = ChangedFlight(PATROL, tmp_path / "run")
    flight.until(lambda: flight.running("corner A"))
    said = [flight.change(command, argument) for command, argument in [
        ("insert", "before \u00b2 LAND"), ("jump", "7" * 5000), ("delete", "-1"), ("update", "INSERT \u00b2 LAND")]]
    said.append(flight.engine.supervisor.execute("insert", MissionChange.insert(3, "").argument))
    said.append(flight.change("update", "INSERT"))
    assert [result.ok for result in said] == [False] * 6
    assert said[0].message == "'\u00b2' is not an item number of the mission (items are numbered 1, 2, 3... in the " \
                              "digits 0-9: aeroexec ctl items lists them)"
    assert said[1].message.startswith("'777777777777777777777777'... (5000 characters) is not an item number")
    assert said[2].message.startswith("'-1' is not an item number")
    assert said[3].message.startswith("update INSERT: '\u00b2' is not an item id")
    assert said[4].message.startswith("insert: the fragment to insert is missing")
    assert said[5].message.startswith("update INSERT: the fragment to insert is missing")
    records = flight.finish()
    assert ended(records) == "completed" and "please report" not in (tmp_path / "run" / "events.jsonl").read_text()


def test_aerostack2_updates_from_ctl_change_a_live_run(tmp_path):
    # a quarter of real time: corner A still flies when a ctl process started on a loaded machine reaches the run
    run = Command(tmp_path, "run", str(PATROL), "--plain", "--speed", "0.25", "--output", str(tmp_path / "out"))
    try:
        run.wait_for("corner A: IDLE -> RUNNING")
        skipped = ctl(tmp_path, "update", "NEXT_ITEM")
        assert skipped.returncode == 0 and "corner A" in skipped.stdout and "skipped" in skipped.stdout
        refused = ctl(tmp_path, "update", "TELEPORT", "2")
        assert refused.returncode == 1 and "Aerostack2's mission update 'TELEPORT' has no meaning here" in \
            refused.stderr
        assert ctl(tmp_path, "update", "STOP").returncode == 0
        code, _, _ = run.finish()
    finally:
        run.process.kill()
    assert code == 4
    records = read_log(tmp_path / "out" / "events.jsonl")
    assert [(r["data"]["command"], r["data"]["ok"]) for r in records if r["kind"] == "mission_change"] == \
        [("skip", True)]


def test_ctl_update_load_without_a_file_is_refused_as_such_not_loading_the_current_folder():
    from aeroexec.cli.ctl import change_argument
    from aeroexec.engine.supervision.changes import parse_aerostack2_update

    argument = change_argument("update", ["LOAD", "3"])
    assert argument == "LOAD 3"
    with pytest.raises(ChangeError, match=r"^update LOAD: the mission file to load is missing \(update LOAD FILE\)$"):
        parse_aerostack2_update(argument)
