"""``aeroexec run --mcap FILE`` (issue 46): the recording is written while the drone flies, by the recorder an
export uses, fed from the event log's lines as they are written: the live file holds what ``aeroexec export``
makes of the run's log afterwards, message for message."""

from __future__ import annotations

import json
import time
from pathlib import Path

from aeroexec.cli.main import main
from aeroexec.flight import FlightSession, FlightSpec
from recordings import assert_monotonic, raw, read_back, records

ROOT = Path(__file__).parents[2]
FIGURE10 = ROOT / "missions" / "figure10.xml"


def test_run_mcap_records_while_flying_what_export_makes_of_the_log(tmp_path, capsys):
    live = tmp_path / "live.mcap"
    assert main(["run", str(FIGURE10), "--plain", "--output", str(tmp_path / "run"), "--mcap", str(live)]) == 0
    assert f"recording: {live}" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.part"))
    assert main(["export", str(tmp_path / "run"), "--mcap", str(tmp_path / "after.mcap")]) == 0
    assert raw(live) == raw(tmp_path / "after.mcap")  # one recorder: the same messages, times and bytes
    found = read_back(live)  # and every message decodes (mcap's ROS 2 decoder, rosbags' Jazzy types)
    assert_monotonic(found)
    states = [r for r in records(tmp_path / "run" / "events.jsonl") if r["kind"] == "state"]
    assert len(found["/drone/pose"]) == len(states) > 10


def test_the_recording_has_the_drone_in_the_air_while_it_is_in_the_air(tmp_path):
    spec = FlightSpec(mission=FIGURE10, output=str(tmp_path / "run"), register=False,
                      mcap=str(tmp_path / "live.mcap"))
    seen: dict[str, float] = {"logged": 0, "z": 0.0}

    def logged(data: bytes) -> None:  # the state samples the event log has written, and the last one's height
        for line in data.decode().splitlines():
            if '"kind":"state"' in line:
                seen["logged"] += 1
                seen["z"] = json.loads(line)["position"][2]

    with FlightSession(spec, notify=lambda text: None) as session:
        session.flight_log.taps.append(logged)

        def airborne() -> None:  # once, in the tick the log first has the drone above 1 m
            if "in_air" in seen or seen["z"] <= 1.0:
                return
            seen["in_air"] = seen["logged"]
            give_up = time.monotonic() + 120  # waits for the recording's thread, not for an amount of time
            while session.recording.recorded("/drone/pose") < seen["in_air"] and time.monotonic() < give_up:
                time.sleep(0.005)
            seen["recorded_in_air"] = session.recording.recorded("/drone/pose")
            seen["flying"] = session.engine.drone.telemetry().position[2] > 1.0

        session.engine.tick_callbacks.append(airborne)
        outcome = session.fly()
    assert outcome.exit_status == 0
    assert seen["flying"] and seen["recorded_in_air"] >= seen["in_air"] > 0
    poses = read_back(tmp_path / "live.mcap")["/drone/pose"]
    assert poses[int(seen["in_air"]) - 1][1].pose.position.z > 1.0  # recorded up there, while there


def test_a_recording_that_cannot_be_written_is_refused_before_anything_flies(tmp_path, capsys):
    target = tmp_path / "missing" / "live.mcap"
    assert main(["run", str(FIGURE10), "--quiet", "--output", str(tmp_path / "run"), "--mcap", str(target)]) == 2
    err = capsys.readouterr().err
    assert f"the recording {target} cannot be written" in err and "Traceback" not in err
    assert not (tmp_path / "run" / "events.jsonl").exists()


def test_fleet_mcap_records_every_drone_while_flying_what_export_makes_of_the_fleets_folder(tmp_path, capsys):
    live = tmp_path / "live.mcap"
    fleet = ROOT / "missions" / "relay.yaml"
    assert main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / "run"), "--mcap", str(live)]) == 0
    assert f"recording in {live}" in capsys.readouterr().err
    assert main(["export", str(tmp_path / "run"), "--mcap", str(tmp_path / "after.mcap")]) == 0
    assert raw(live) == raw(tmp_path / "after.mcap")
    found = read_back(live)
    assert_monotonic(found)
    for drone in ("scout", "carrier"):
        states = [r for r in records(tmp_path / "run" / drone / "events.jsonl") if r["kind"] == "state"]
        assert len(found[f"/{drone}/pose"]) == len(states) > 10
    assert main(["fleet", str(fleet), "--quiet", "--workers", "2", "--output", str(tmp_path / "w"),
                 "--mcap", str(tmp_path / "w.mcap")]) == 2
    assert "--mcap needs every drone in this process: use --workers 1" in capsys.readouterr().err


def test_a_recording_that_fails_in_flight_is_given_up_said_and_the_run_not_reported_whole(tmp_path, monkeypatch,
                                                                                           capsys):
    from aeroexec.flight.recording.mcap_file import McapFile

    written = {"n": 0}
    write = McapFile.write

    def full_disk(self, channel, log_time, data):  # the disk fills up after 100 messages
        written["n"] += 1
        if written["n"] > 100:
            raise OSError(28, "No space left on device")
        write(self, channel, log_time, data)

    monkeypatch.setattr(McapFile, "write", full_disk)
    target = tmp_path / "live.mcap"
    code = main(["run", str(FIGURE10), "--quiet", "--output", str(tmp_path / "run"), "--mcap", str(target)])
    err = capsys.readouterr().err
    assert code == 6, err
    assert f"the recording {target}: OSError: [Errno 28] No space left on device" in err
    log = records(tmp_path / "run" / "events.jsonl")
    assert log[-1]["kind"] == "log_closed" and [r for r in log if r["kind"] == "drone_landed"]  # flown, landed
    assert not target.exists() and not list(tmp_path.glob("*.part"))
