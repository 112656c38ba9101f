"""`aeroexec fleet FLEET.yaml`: several drones in one process and one world, linked over Zenoh."""

import json
from pathlib import Path

import pytest
from aeroexec.cli.main import main

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


def events(folder: Path, drone: str) -> list[dict]:
    return [json.loads(line) for line in (folder / drone / "events.jsonl").read_text().splitlines()]


def test_the_fleet_search_lands_every_drone_with_marker_3_known_to_all_over_zenoh(tmp_path, capsys):
    code = main(["fleet", str(MISSIONS / "fleet_search.yaml"), "--plain", "--output", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    summary = [line for line in err.splitlines() if line.startswith(("d1:", "d2:", "d3:"))]
    assert len(summary) == 3 and all("completed" in line and "landed" in line for line in summary), summary
    finders, told = [], []
    for drone in ("d1", "d2", "d3"):
        log = events(tmp_path, drone)
        if any(e["kind"] == "message_sent" for e in log):
            finders.append(drone)
        arrived = [e for e in log if e["kind"] == "fleet_belief" and "object(marker_3" in e.get("detail", "")]
        if arrived:
            told.append(drone)
        assert any(e["kind"] == "belief_added" and e.get("belief", "").startswith("code(marker_3, 3)")
                   for e in log), f"{drone} never knew marker 3"
        assert log[-2]["kind"] == "engine_stopped" or any(e["kind"] == "mission_completed" for e in log)
    assert finders and told, (finders, told)  # found by one, known to the others over the link
    for drone in {"d1", "d2", "d3"} - set(finders):  # whoever did not broadcast it heard of it
        assert drone in told or any(f"{drone} | " in line and f"message_received: from {finder}: marker 3 found"
                                    in line for line in out.splitlines() for finder in finders), drone


def test_the_relay_carrier_takes_off_only_after_the_scouts_message_the_same_in_every_run(tmp_path, capsys):
    """What a drone hears of the fleet, and when, does not depend on the load: a fleet flown again with the same
    seeds writes the same event logs."""
    for run in ("first", "again"):
        assert main(["fleet", str(MISSIONS / "relay.yaml"), "--plain", "--output", str(tmp_path / run)]) == 0
    log = events(tmp_path / "first", "carrier")
    received = next(e for e in log if e["kind"] == "message_received")
    take_off = next(e for e in log if e["kind"] == "activated" and e["behavior"] == "TAKE_OFF")
    assert received["data"]["sender"] == "scout" and received["data"]["text"] == "area clear"
    assert take_off["time"] >= received["time"]
    for drone in ("scout", "carrier"):
        first, again = events(tmp_path / "first", drone), events(tmp_path / "again", drone)
        assert first[0]["output"] != again[0]["output"] and first[1:] == again[1:], drone


def test_drones_of_one_world_see_each_other_and_know_where_the_others_are_whatever_their_names(tmp_path):
    """Names hold -, . and _ as Zenoh key chunks and file names do; in beliefs they are quoted atoms."""
    fleet = tmp_path / "pair.yaml"
    mission = tmp_path / "look.py"
    mission.write_text("import aeroexec.engine.api as api\n\n\ndef mission():\n"
                       "    _, me = api.consult_belief('position(self, (?X, ?Y, ?Z))')\n"
                       "    other = 'b.2' if me['?X'] < 2 else 'a-1'\n"
                       "    api.execute_behavior('TAKE_OFF', altitude=2)\n"
                       "    api.activate_behavior('PAY_ATTENTION_TO_SHAPES')\n"
                       "    api.wait(3)\n"
                       "    if not api.true_belief(f'position(\"{other}\", ?P)'):\n"
                       "        raise RuntimeError(f'where is {other}?')\n"
                       "    if other == 'b.2' and not api.true_belief('object(\"b.2\", drone)'):\n"
                       "        raise RuntimeError('a-1 does not see b.2, 4 m ahead of it')\n"
                       "    api.execute_behavior('LAND')\n")
    fleet.write_text("fleet: pair-team\ndrones:\n  - {name: a-1, mission: look.py, home: [0, 0]}\n"
                     "  - {name: b.2, mission: look.py, home: [4, 0]}\n")
    assert main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / "out")]) == 0
    for drone, other in (("a-1", "b.2"), ("b.2", "a-1")):  # each asked where the other is, and was answered
        log = events(tmp_path / "out", drone)
        assert any(e["kind"] == "fleet_drone_heard" and e["data"]["drones"] == [other] for e in log), drone
        assert any(e["kind"] == "mission_completed" for e in log), drone


@pytest.mark.parametrize(("text", "expected"), [
    ("fleet: f\ndrones:\n  - {name: d1, mission: nowhere.py}\n",
     "f.yaml:3: error: the mission nowhere.py is not found"),
    ("fleet: f\ndrones:\n  - {name: d1, mission: m.py}\n  - {name: d1, mission: m.py}\n",
     "f.yaml:4: error: two drones are called d1 (the first at line 3)"),
    ("fleet: f\ndrones:\n  - {name: d1, mission: m.py, home: [1]}\n",
     "f.yaml:3: error: the home of d1 must be [east, north] in meters"),
    ("fleet: 'my fleet'\ndrones:\n  - {name: d1, mission: m.py}\n", "f.yaml:1: error: the fleet's name"),
    ("fleet: f\ndrones:\n  - {name: d1, mision: m.py}\n", "f.yaml:3: error: a drone: unknown key mision"),
    ("fleet: f\ndrones:\n  - {name: d1., mission: m.py}\n", "f.yaml:3: error: a drone's name (name:) 'd1.' must "
                                                             "start with a letter and hold only letters, digits, _, -"),
    ("fleet: f\ndrones:\n  - {name: router, mission: m.py}\n",
     "f.yaml:3: error: the drone name router is reserved for the fleet's credentials (router.pem)"),
    ("fleet: f\ndrones:\n  - {name: operator, mission: m.py}\n",
     "f.yaml:3: error: the drone operator has the name of an operator (operators:)"),
    ("fleet: f\ndrones:\n  - {name: d1, mission: m.py, key: d1.key}\n",
     "f.yaml:3: error: the drone d1 names a key without its certificate: give certificate:"),
    ("fleet: f\ndrones:\n  - {name: d1}\n", "f.yaml: no drone has a mission: nothing flies here"),
    # trust: a predicate's name some drone shares, and a number of members a drone can hear it from
    ("fleet: f\nshare: [code]\ntrust: {Code(x): 2}\ndrones:\n  - {name: d1, mission: m.py}\n",
     "f.yaml:3: error: trust: 'Code(x)' is no predicate's name (letters, digits and _, not a digit first)"),
    ("fleet: f\nshare: [code]\ntrust:\n  object: 2\ndrones:\n  - {name: d1, mission: m.py}\n  - {name: d2}\n"
     "  - {name: d3}\n",
     "f.yaml:4: error: trust: no drone shares object (share:), so no drone hears it from another"),
    ("fleet: f\nshare: [code]\ntrust:\n  code: 3\ndrones:\n  - {name: d1, mission: m.py}\n  - {name: d2}\n"
     "  - {name: d3}\n",
     "f.yaml:4: error: trust: code: 3 members must agree, but 3 drones share it, so a drone that shares it hears it "
     "from at most 2: give 1 to 2"),
    ("fleet: f\nshare: [code]\ntrust: {code: 0}\ndrones:\n  - {name: d1, mission: m.py}\n",
     "f.yaml:3: error: trust: code must be a whole number of at least 1, not '0'"),
    ("fleet: f\nshare: [code]\ntrust: [code]\ndrones:\n  - {name: d1, mission: m.py}\n",
     "f.yaml:3: error: trust must be a mapping of keys to values"),
    ("fleet: f\ncredentials: nowhere\ndrones:\n  - {name: d1, mission: m.py}\n",
     "f.yaml: the credentials folder nowhere is not there: make it with aeroexec fleet f.yaml --make-credentials "
     "nowhere"),
])
def test_fleet_file_errors_name_file_and_line(tmp_path, capsys, text, expected):
    (tmp_path / "m.py").write_text("def mission():\n    pass\n")
    (tmp_path / "f.yaml").write_text(text)
    assert main(["fleet", str(tmp_path / "f.yaml"), "--output", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert expected in err.replace(str(tmp_path) + "/", ""), err
    assert "Traceback" not in err


def test_a_fleet_flies_missions_of_any_format_side_by_side(tmp_path, capsys):
    fleet = tmp_path / "mixed.yaml"
    fleet.write_text(f"fleet: mixed\ndrones:\n  - {{name: t1, mission: {MISSIONS / 'square_patrol.yaml'}}}\n"
                     f"  - {{name: p1, mission: {MISSIONS / 'relay_scout.py'}, home: [2, 2]}}\n")
    assert main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "t1: square_patrol.yaml completed" in err and "p1: relay_scout.py completed" in err
    tree = events(tmp_path / "out", "t1")
    assert any(e["kind"] == "node_status" for e in tree)  # flown as a behavior tree
    scout = events(tmp_path / "out", "p1")
    heard = next(e for e in scout if e["kind"] == "message_sent")
    assert heard["data"]["receivers"] == ["t1"]


GO_EAST = '''"""Take off, fly 12 m east at the vehicle's cruise speed, land."""

import aeroexec.engine.api as api


def runMission():
    api.executeBehavior("TAKE_OFF")
    api.executeBehavior("GO_TO_POINT", point=[12, 0, 2])
    api.executeBehavior("LAND")
'''


def test_each_drone_of_a_fleet_flies_with_its_vehicle_profile_and_a_wrong_one_is_named_at_its_line(tmp_path, capsys):
    """``vehicle:`` gives every drone of the fleet a profile; a drone's own ``vehicle:`` is its own (a slow
    fleet-wide cruise speed of 1 m/s, d2's own 8 m/s): each go-to takes its profile's time."""
    (tmp_path / "east.py").write_text(GO_EAST)
    (tmp_path / "slow.yaml").write_text("cruise_speed: 1\n")
    (tmp_path / "fast.yaml").write_text("cruise_speed: 8\nmax_speed: 12\n")
    fleet = tmp_path / "pair.yaml"
    fleet.write_text("fleet: pair\nvehicle: slow.yaml\ndrones:\n  - {name: d1, mission: east.py}\n"
                     "  - {name: d2, mission: east.py, home: [3, 3], vehicle: fast.yaml}\n")
    assert main(["fleet", str(fleet), "--plain", "--output", str(tmp_path / "out")]) == 0, capsys.readouterr().err

    def go_to_took(drone: str) -> float:
        log = events(tmp_path / "out", drone)
        began = next(e["time"] for e in log if e["kind"] == "activated" and e["behavior"] == "GO_TO_POINT")
        return next(e["time"] for e in log if e["kind"] == "activated" and e["behavior"] == "LAND") - began

    assert go_to_took("d1") > 10.0 > 2 * go_to_took("d2"), (go_to_took("d1"), go_to_took("d2"))

    (tmp_path / "fast.yaml").write_text("cruise_speed: fast\n")
    capsys.readouterr()
    assert main(["fleet", str(fleet), "--plain", "--output", str(tmp_path / "again")]) != 0
    err = capsys.readouterr().err
    assert f"{fleet}:5: " in err and "cruise_speed (m/s) must be a number, not 'fast'" in err, err
    assert "Traceback" not in err


def test_a_fleet_flies_with_a_larger_young_generation_in_the_command_s_own_process_only(tmp_path):
    """The command's own process collects what a fleet's periods keep every YOUNG_GENERATION objects while it flies,
    and sets the collector back after; a caller running ``main(args)`` in its own process keeps its collector as it
    is."""
    import subprocess
    import sys
    import textwrap

    (tmp_path / "hop.py").write_text("import aeroexec.engine.api as api\n\n\ndef mission():\n"
                                     "    api.execute_behavior('TAKE_OFF', altitude=2)\n"
                                     "    api.execute_behavior('LAND')\n")
    (tmp_path / "pair.yaml").write_text("fleet: pair\ndrones:\n  - {name: a, mission: hop.py, home: [0, 0]}\n"
                                        "  - {name: b, mission: hop.py, home: [4, 0]}\n")
    code = f"""
        import contextlib, gc, io, sys
        from aeroexec.cli.main import main
        from aeroexec.flight.fleet.fleet_flight import FleetFlight, YOUNG_GENERATION
        seen = []
        loop = FleetFlight._loop
        def watched(self, max_time):
            seen.append(gc.get_threshold()[0])
            loop(self, max_time)
        FleetFlight._loop = watched
        before = gc.get_threshold()
        arguments = ["fleet", {str(tmp_path / "pair.yaml")!r}, "--quiet", "--output"]
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert main(arguments + [{str(tmp_path / "embedded")!r}]) == 0
        sys.argv = ["aeroexec", *arguments, {str(tmp_path / "command")!r}]
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert main() == 0
        print(seen == [before[0], YOUNG_GENERATION], gc.get_threshold() == before, file=sys.stderr)
    """
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, cwd="/")
    assert done.stderr.split()[-2:] == ["True", "True"], done.stderr
