"""``aeroexec export RUN_DIR --mcap FILE`` (issue 46): a flown run's recording read back by two independent readers —
``mcap`` with mcap-ros2-support's decoder, and ``rosbags``' typestore of ROS 2 Jazzy, which decodes the CDR messages
with its own definitions of the types, not the file's — with timestamps that never go back on a topic and as many
messages as the event log has records."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import pytest
from aeroexec.cli.main import main
from aeroexec.drones.geodesy import enu_to_geodetic
from aeroexec.engine.events import Outcome
from recordings import JAZZY, assert_monotonic, read_back, records, schemas
from rosbags.typesys import get_types_from_msg

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"
BEHAVIOR_KINDS = {"activated", "failed_preconditions", "rejected", *(o.value for o in Outcome)}


def fly_and_export(tmp_path: Path, *argv: str) -> Path:
    assert main([*argv, "--quiet", "--output", str(tmp_path / "run")]) == 0
    target = tmp_path / "flight.mcap"
    assert main(["export", str(tmp_path / "run"), "--mcap", str(target)]) == 0
    return target


def test_figure10_exported_reads_back_with_mcap_and_rosbags_as_many_messages_as_the_log_has_records(tmp_path,
                                                                                                    capsys):
    target = fly_and_export(tmp_path, "run", str(MISSIONS / "figure10.xml"))
    assert capsys.readouterr().out.splitlines()[-1] == str(target)
    log = records(tmp_path / "run" / "events.jsonl")
    found = read_back(target)
    assert_monotonic(found)
    states = [r for r in log if r["kind"] == "state"]
    for topic in ("/drone/pose", "/drone/velocity", "/drone/fix", "/drone/battery", "/tf"):
        assert len(found[topic]) == len(states), topic
    kinds = Counter(r["kind"] for r in log)
    assert len(found["/drone/behavior_events"]) == sum(kinds[k] for k in BEHAVIOR_KINDS) > 0
    assert len(found["/drone/beliefs"]) == kinds["belief_added"] + kinds["belief_removed"] > 0
    assert len(found["/drone/tree"]) == kinds["node_status"] > 0
    json_topics = [t for t, messages in found.items() if messages[0][2] is None]
    assert sum(len(found[t]) for t in json_topics) == len(log) - len(states) - 2  # log_started, log_closed: metadata
    # what the drone did, as ROS 2 messages, in both readers
    home = tuple(log[0]["home"])
    for state, (t, pose, rosbags_pose), (_, fix, _), (_, battery, rosbags_battery), (_, tf, _) in zip(
            states, found["/drone/pose"], found["/drone/fix"], found["/drone/battery"], found["/tf"], strict=True):
        assert t == round(state["time"] * 1e9)
        position = [pose.pose.position.x, pose.pose.position.y, pose.pose.position.z]
        assert position == state["position"]
        assert [rosbags_pose.pose.position.x, rosbags_pose.pose.position.y, rosbags_pose.pose.position.z] == position
        assert (pose.header.stamp.sec, pose.header.stamp.nanosec) == divmod(t, 10**9)
        assert pose.header.frame_id == "world"
        yaw = math.degrees(2 * math.atan2(pose.pose.orientation.z, pose.pose.orientation.w))
        assert yaw == pytest.approx(state["yaw"], abs=1e-6)
        assert battery.percentage == pytest.approx(state["battery"] / 100) == rosbags_battery.percentage
        assert (fix.latitude, fix.longitude, fix.altitude) == pytest.approx(enu_to_geodetic(state["position"], home))
        assert [(x.header.frame_id, x.child_frame_id) for x in tf.transforms] == [("world", "drone")]
    assert max(s["position"][2] for s in states) > 1.0  # it flew
    # the planned route: from home through the mission's literal destinations (the way back is read from the
    # blackboard in flight: not a literal one)
    [(_, path, rosbags_path)] = found["/drone/route"]
    points = [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in path.poses]
    assert points == [(0.0, 0.0, 0.0), (2.0, 5.0, 1.3)] and len(rosbags_path.poses) == 2
    assert all(isinstance(m[1], dict) and m[1]["kind"] == "node_status" for m in found["/drone/tree"])


def test_the_definitions_are_rosbag2s_and_say_what_rosbags_jazzy_types_say(tmp_path):
    target = fly_and_export(tmp_path, "run", str(MISSIONS / "figure10.xml"))
    ros = {name: text for name, text in schemas(target).values() if "/msg/" in name}
    assert set(ros) == {"geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/TwistStamped",
                        "sensor_msgs/msg/NavSatFix", "sensor_msgs/msg/BatteryState", "tf2_msgs/msg/TFMessage",
                        "nav_msgs/msg/Path"}
    for name, text in ros.items():
        parsed = get_types_from_msg(text, name)  # the top type and every dependency, from the file's text alone
        for type_name, (constants, fields) in parsed.items():
            assert fields == JAZZY.fielddefs[type_name][1], type_name
            assert sorted(constants) == sorted(JAZZY.fielddefs[type_name][0]), type_name
    # rosbag2's layout: the type's own text, then its dependencies, sorted, depth first, after 80 '=' and MSG:
    fix = ros["sensor_msgs/msg/NavSatFix"]
    delimiter = "\n" + "=" * 80 + "\nMSG: "
    assert [part.split("\n", 1)[0] for part in fix.split(delimiter)[1:]] == [
        "sensor_msgs/NavSatStatus", "std_msgs/Header", "builtin_interfaces/Time"]


def test_a_fleet_exports_into_one_file_with_each_drones_topics_and_frames(tmp_path):
    target = fly_and_export(tmp_path, "fleet", str(MISSIONS / "relay.yaml"))
    found = read_back(target)
    assert_monotonic(found)
    transforms = Counter()
    for _, tf, rosbags_tf in found["/tf"]:
        assert len(tf.transforms) == len(rosbags_tf.transforms) == 1
        transforms[tf.transforms[0].child_frame_id] += 1
    for drone in ("scout", "carrier"):
        log = records(tmp_path / "run" / drone / "events.jsonl")
        states = [r for r in log if r["kind"] == "state"]
        assert len(found[f"/{drone}/pose"]) == len(found[f"/{drone}/battery"]) == transforms[drone] == len(states)
        assert [[m.pose.position.x, m.pose.position.y, m.pose.position.z] for _, m, _ in found[f"/{drone}/pose"]] \
            == [s["position"] for s in states]
        kinds = Counter(r["kind"] for r in log)
        assert len(found[f"/{drone}/behavior_events"]) == sum(kinds[k] for k in BEHAVIOR_KINDS) > 0
        assert len(found[f"/{drone}/beliefs"]) == kinds["belief_added"] + kinds["belief_removed"]
    assert set(transforms) == {"scout", "carrier"}
    assert not [t for t in found if t.startswith("/drone/")]


def export(*argv: str) -> int:
    return main(["export", *argv])


def test_a_folder_that_is_not_a_run_is_refused_naming_it(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("hello\n")
    assert export(str(tmp_path), "--mcap", str(tmp_path / "x.mcap")) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"aeroexec export: {tmp_path}: not a run's output folder") and "Traceback" not in err
    assert not (tmp_path / "x.mcap").exists()
    assert export(str(tmp_path / "nowhere"), "--mcap", str(tmp_path / "x.mcap")) == 1
    assert "nowhere: no such folder" in capsys.readouterr().err


def test_a_cut_line_of_the_event_log_is_refused_with_its_file_and_line_and_no_file_left(tmp_path, capsys):
    assert main(["run", str(MISSIONS / "figure10.xml"), "--quiet", "--output", str(tmp_path / "run")]) == 0
    log = tmp_path / "run" / "events.jsonl"
    lines = log.read_text().splitlines(keepends=True)
    lines[40] = lines[40][:25] + "\n"  # a line cut short in the middle of the log
    log.write_text("".join(lines))
    capsys.readouterr()
    target = tmp_path / "x.mcap"
    assert export(str(tmp_path / "run"), "--mcap", str(target)) == 1
    err = capsys.readouterr().err.strip()
    assert err == f"aeroexec export: {log}:41: not a JSON object"
    assert not target.exists() and not list(tmp_path.glob("*.part"))
    lines[40] = '{"time":"soon","kind":"state"}\n'  # JSON, but no engine time
    log.write_text("".join(lines))
    assert export(str(tmp_path / "run"), "--mcap", str(target)) == 1
    assert capsys.readouterr().err.strip() == f"aeroexec export: {log}:41: a record without its time (engine seconds)"
    lines[40] = '{"time":3.0,"kind":"state","position":[1,2],"velocity":[0,0,0],"yaw":0,"battery":90}\n'
    log.write_text("".join(lines))
    assert export(str(tmp_path / "run"), "--mcap", str(target)) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"aeroexec export: {log}:41: a state record that cannot be recorded")
    assert "Traceback" not in err
    assert not target.exists() and not list(tmp_path.glob("*.part"))


def test_a_last_line_torn_by_a_crash_is_left_out_and_said(tmp_path, capsys, caplog):
    assert main(["run", str(MISSIONS / "figure10.xml"), "--quiet", "--output", str(tmp_path / "run")]) == 0
    log = tmp_path / "run" / "events.jsonl"
    text = log.read_text()
    whole = len(text.splitlines())
    log.write_text(text + '{"time":12.0,"kind":"sta')  # what a killed process leaves
    capsys.readouterr()
    assert export(str(tmp_path / "run"), "--mcap", str(tmp_path / "x.mcap")) == 0
    assert f"{log}: the last line is incomplete and was left out" in caplog.text  # a WARNING line on stderr
    found = read_back(tmp_path / "x.mcap")
    assert sum(len(m) for t, m in found.items() if t not in ("/drone/velocity", "/drone/fix", "/drone/battery",
                                                             "/tf", "/drone/route")) == whole - 2


def test_a_mission_file_changed_since_the_flight_leaves_the_route_out_and_the_rest_recorded(tmp_path, capsys, caplog):
    mission = tmp_path / "m.xml"
    mission.write_text((MISSIONS / "figure10.xml").read_text())
    assert main(["run", str(mission), "--quiet", "--output", str(tmp_path / "run")]) == 0
    mission.write_text("<root BTCPP_format='4'><BehaviorTree ID='M'><Sequence>")  # cut short since
    assert export(str(tmp_path / "run"), "--mcap", str(tmp_path / "x.mcap")) == 0
    assert "no planned route" in caplog.text
    found = read_back(tmp_path / "x.mcap")
    assert "/drone/route" not in found and len(found["/drone/pose"]) > 10
    mission.unlink()  # gone
    assert export(str(tmp_path / "run"), "--mcap", str(tmp_path / "y.mcap")) == 0
    assert f"aeroexec export: {mission}: the mission file is not there: no planned route" in capsys.readouterr().err
