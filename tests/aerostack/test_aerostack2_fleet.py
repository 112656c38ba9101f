"""Aerostack2 scripts that drive several ``DroneInterface`` objects fly as a fleet: the drones of a fleet file that
name one script fly it together (it runs once, each interface bound to its drone by namespace), on one clock."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from aeroexec.cli.main import main
from aeroexec.flight.missions import script_drones
from flying import EMPTY_WORLD, SCRIPTS


def fleet_file(tmp_path: Path, name: str, script: str, drones: dict[str, tuple[float, float]]) -> Path:
    path = tmp_path / f"{name}.yaml"  # ours: the drones and starts of the project's config/world_swarm.yaml
    lines = [f"fleet: {name}", f"world: {EMPTY_WORLD}", "drones:"]
    lines += [f"  - {{name: {d}, mission: {SCRIPTS / script}, home: [{x}, {y}]}}" for d, (x, y) in drones.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


def answers(tmp_path: Path, replies: dict[str, str]) -> Path:
    path = tmp_path / "answers.yaml"
    path.write_text("".join(f'"{question}": {reply}\n' for question, reply in replies.items()))
    return path


def events(folder: Path, drone: str) -> list[dict]:
    return [json.loads(line) for line in (folder / drone / "events.jsonl").read_text().splitlines()]


def test_the_swarm_script_flies_its_three_drones_as_a_fleet(tmp_path, capsys):
    fleet = fleet_file(tmp_path, "swarm", "gazebo_mission_swarm.py",
                       {"drone0": (-2.0, 0.0), "drone1": (2.0, 0.0), "drone2": (0.0, 0.0)})
    replies = answers(tmp_path, {"Takeoff? (y/n):": "y", "Go to? (y/n):": "y", "Replay? (y/n):": "n",
                                 "Land? (y/n):": "y"})
    out = tmp_path / "out"
    status = main(["fleet", str(fleet), "--plain", "--output", str(out), "--answers", str(replies)])
    err = capsys.readouterr().err
    assert status == 0, err
    for drone in ("drone0", "drone1", "drone2"):
        log = events(out, drone)
        goals = [r["behavior"] for r in log if r["kind"] == "GOAL_ACHIEVED" and r["behavior"] in
                 ("TAKE_OFF", "GO_TO_POINT", "LAND")]
        assert goals[0] == "TAKE_OFF" and goals[-1] == "LAND" and goals.count("GO_TO_POINT") >= 9, (drone, goals)
        assert [r["kind"] for r in log if r["kind"].startswith("mission_")] == ["mission_started",
                                                                               "mission_completed"]
        assert f"{drone}: gazebo_mission_swarm.py completed at" in err
    # the three take off together (take-offs not waited for, then polled), and dance in formation
    take_offs = [next(r["time"] for r in events(out, d) if r["kind"] == "activated" and r["behavior"] == "TAKE_OFF")
                 for d in ("drone0", "drone1", "drone2")]
    assert max(take_offs) - min(take_offs) < 0.2
    first_goals = [next(r["detail"] for r in events(out, d) if r["kind"] == "activated"
                        and r["behavior"] == "GO_TO_POINT") for d in ("drone0", "drone1", "drone2")]
    assert len(set(first_goals)) == 3  # each drone its own place of the triangle
    questions = [r["detail"] for r in events(out, "drone0") if r["kind"] == "operator" and r["data"].get("action")
                 == "answer"]
    assert questions == ["Takeoff? (y/n): y", "Go to? (y/n): y", "Replay? (y/n): n", "Land? (y/n): y"]


def test_a_fleet_script_flying_to_tf_frames_is_refused_before_flight(tmp_path, capsys):
    """The gates are frames of ROS 2's tf tree, reaching go_to through a dict: each request was refused in flight,
    after the take-off, and the run failed; now the fleet is refused before any drone flies, at the calls."""
    fleet = fleet_file(tmp_path, "gates", "hands_on_mission.py", {"cf0": (0.0, 0.0), "cf1": (0.0, 2.0)})
    out = tmp_path / "out"
    status = main(["fleet", str(fleet), "--plain", "--output", str(out)])
    err = capsys.readouterr().err
    assert status == 1
    assert not list(out.rglob("events.jsonl"))  # no drone flew
    assert "hands_on_mission.py:39:50: error: WRONG_VALUE: The frame of go_to.go_to_point_path_facing() is not " \
           "known before flight, and the script names frames of ROS 2's tf tree ('gate_0/gate_link' (line 194)" in err


def test_a_script_naming_a_drone_the_fleet_does_not_have_fails_saying_which(tmp_path, capsys):
    fleet = fleet_file(tmp_path, "pair", "as2_try_multiple_drone.py", {"drone_sim_0": (0.0, 0.0), "other": (2.0, 0.0)})
    out = tmp_path / "out"
    assert main(["fleet", str(fleet), "--plain", "--output", str(out)]) == 1
    failed = [r["detail"] for r in events(out, "other") if r["kind"] == "mission_failed"]
    assert failed and "DroneNotFound: no drone named drone_sim_1 in this fleet (its drones: drone_sim_0, other)" in \
        failed[0]


def test_aeroexec_run_flies_a_swarm_script_as_a_fleet_made_for_it(tmp_path, capsys):
    # `python3 mission_swarm.py` for an Aerostack2 user: here `aeroexec run mission_swarm.py`, no fleet file
    replies = answers(tmp_path, {"Takeoff? (y/n):": "y", "Go to? (y/n):": "y", "Replay? (y/n):": "n",
                                 "Land? (y/n):": "y"})
    out = tmp_path / "out"
    status = main(["run", str(SCRIPTS / "gazebo_mission_swarm.py"), "--plain", "--output", str(out),
                   "--answers", str(replies)])
    err = capsys.readouterr().err
    assert status == 0, err
    assert "gazebo_mission_swarm.py flies 3 drones (drone0, drone1, drone2), 2 m apart, as a fleet" in err
    starts = set()
    for drone in ("drone0", "drone1", "drone2"):
        log = events(out, drone)
        goals = [r["behavior"] for r in log if r["kind"] == "GOAL_ACHIEVED" and r["behavior"] in
                 ("TAKE_OFF", "GO_TO_POINT", "LAND")]
        assert goals[0] == "TAKE_OFF" and goals[-1] == "LAND" and goals.count("GO_TO_POINT") >= 9, (drone, goals)
        assert f"{drone}: gazebo_mission_swarm.py completed at" in err
        state = next(r for r in log if r["kind"] == "state")
        starts.add((round(state["position"][0], 1), round(state["position"][1], 1)))
    assert len(starts) == 3  # each drone from its own start, apart
    assert json.loads((out / "fleet_status.json").read_text())["drones"].keys() == {"drone0", "drone1", "drone2"}


@pytest.mark.parametrize("script, drones", [
    ("as2_try_multiple_drone.py", ("drone_sim_0", "drone_sim_1")),  # DroneInterface('drone_sim_0')...
    ("gazebo_mission_swarm.py", ("drone0", "drone1", "drone2")),  # argparse: --namespaces, its default list
    ("crazyflie_mission_swarm.py", ("cf0", "cf1", "cf2")),
    ("hands_on_mission.py", ("cf0", "cf1")),
    ("rosconches24_mission_leader.py", ("drone0", "drone1", "drone2")),  # --leader_namespace, then --namespaces
    ("gazebo_mission.py", ("drone0",)),  # one drone: the run flies it alone
])
def test_the_drones_a_script_flies_are_read_from_its_source(script, drones):
    assert script_drones(SCRIPTS / script) == drones
