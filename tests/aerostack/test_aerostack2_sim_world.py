"""An Aerostack2 project launches Gazebo from its own world config (``sim_config/world.json``): run alone, its
script flies in that world, from where the config spawns the drone, and a point given in an object's frame
(``gate_0/link``) is flown to where the config places the object. A frame the world does not place stays refused."""

from __future__ import annotations

import csv
import json
import math
import shutil
from pathlib import Path

from aeroexec.cli.main import main
from aeroexec.drones.sim.world import Frame
from aeroexec.engine.missions.check import check_mission_source
from aeroexec.trees.mission_world import mission_world
from flying import DATA, fly

HELDBACK = DATA / "heldback"
GATES = HELDBACK / "aerostack2__project_crazyflie_gates"
JACKET = HELDBACK / "jackha02__project_gazebo"


def gates(config: Path, drone: str = "cf0") -> dict[str, tuple[tuple[float, float, float], float]]:
    """The gates of a world config as its author wrote them: name -> (position from the drone's spawn, yaw)."""
    data = json.loads(config.read_text())
    spawn = next(d["xyz"] for d in data["drones"] if d["model_name"] == drone)
    return {o["model_name"]: ((o["xyz"][0] - spawn[0], o["xyz"][1] - spawn[1], o["xyz"][2]), o["rpy"][2])
            for o in data["objects"]}


def crossings(states: list[dict], center: tuple[float, float, float], yaw: float, height: float) -> list[float]:
    """How far from the gate's opening (``height`` above its frame's origin) the track crosses the gate's plane
    (through its frame's origin, across its x axis), at each crossing within 1.5 m of the gate (a gate's width:
    the plane crossed farther away is not the gate)."""
    axis = (math.cos(yaw), math.sin(yaw))
    found = []
    for a, b in zip(states, states[1:], strict=False):
        (ax, ay, az), (bx, by, bz) = a["position"], b["position"]
        da = (ax - center[0]) * axis[0] + (ay - center[1]) * axis[1]
        db = (bx - center[0]) * axis[0] + (by - center[1]) * axis[1]
        if da * db < 0:
            t = da / (da - db)
            x, y, z = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
            if math.dist((x, y), center[:2]) < 1.5:
                found.append(math.dist((x, y, z), (center[0], center[1], center[2] + height)))
    return found


def test_a_frame_of_the_world_gives_points_in_the_objects_pose():
    gate = Frame("gate_1/link", (2.0, 1.5, 0.0), (0.0, 0.0, math.pi / 2))  # turned a quarter: its x looks north
    assert gate.to_world((1.0, 0.0, 0.8)) == (2.0, 2.5, 0.8)
    assert gate.to_world((-1.0, 0.0, 0.8)) == (2.0, 0.5, 0.8)


def test_the_project_world_config_its_launch_file_picks_for_the_scripts_drones():
    single, swarm = mission_world(GATES / "mission.py"), mission_world(GATES / "mission_swarm.py")
    assert single.name.endswith("(as Gazebo's empty world, sim_config/world.json)")  # ['cf0']
    assert swarm.name.endswith("(as Gazebo's empty world, sim_config/world_swarm.json)")  # ['cf0', 'cf1']
    written = gates(GATES / "sim_config" / "world.json")
    assert {f.name: f.position for f in single.frames} == {f"{n}/link": p for n, (p, _) in written.items()}


def test_the_gates_script_flies_through_both_gates_frames_from_aeroexec_run_alone(tmp_path, capsys):
    """Through each gate's frame at the point the script asks (its no-flags height, 0.8 m: in Gazebo's world the
    gate model's pole, below its opening; the solids are not simulated, docs/missions/aerostack2-run.md)."""
    flight = fly(GATES / "mission.py", tmp_path, capsys, world_file=None)
    states = [r for r in flight.kinds("state") if r["landed_state"] == "in_air"]
    for _name, (center, yaw) in gates(GATES / "sim_config" / "world.json").items():
        passes = crossings(states, center, yaw, 0.8)  # the script's gate height without -s (its "real mode")
        assert len(passes) == 2 and all(d < 0.3 for d in passes), (_name, passes)  # a path, then its "Replay"
    assert len(flight.kinds("drone_landed")) == 1 and flight.achieved()[-1] == "LAND"
    # the script ends in its own shutdown_all(): sys.exit(1), after the landing, as under python3
    assert flight.status == 1 and "ScriptExit: the script exited with status 1" in flight.err
    assert "refused" not in flight.err


def test_a_frame_the_world_config_does_not_place_stays_refused_before_flight(tmp_path, capsys):
    project = tmp_path / "project"
    shutil.copytree(GATES, project)
    config = project / "sim_config" / "world.json"
    data = json.loads(config.read_text())
    data["objects"] = [o for o in data["objects"] if o["model_name"] != "gate_1"]
    config.write_text(json.dumps(data))
    flight = fly(project / "mission.py", tmp_path, capsys, world_file=None)
    assert flight.status == 1 and "the mission will not fly" in flight.err
    assert "'gate_1/link' (line 195)) that are not frames of the world (gate_0/link" in flight.err
    assert flight.records == []  # refused before flight: no take-off, no event log


def test_the_jacket_inspection_flies_the_joints_its_project_keeps(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(JACKET)  # as the project's session runs it: config/joints.csv from the project's folder
    flight = fly(JACKET / "jacket_inspection_single.py", tmp_path, capsys, world_file=None)
    assert flight.status == 0, flight.err
    with (JACKET / "config" / "joints.csv").open() as file:
        joints = [(float(r["x"]), float(r["y"]), float(r["z"])) for r in csv.DictReader(file)]
    goals = [r["arguments"]["COORDINATES"] for r in flight.kinds("activated") if r["behavior"] == "GO_TO_POINT"]
    assert [tuple(g) for g in goals] == [j for j in joints if j in map(tuple, goals)]  # in the file's order
    assert all(min(math.dist(j, g) for g in goals) < 0.01 for j in joints)  # twins 1e-10 m apart: already there
    assert flight.achieved() == ["TAKE_OFF", *["GO_TO_POINT"] * len(joints), "LAND"]


def test_the_gates_swarm_flies_each_drone_from_its_spawn_through_both_gates_frames(tmp_path, capsys):
    out = tmp_path / "out"
    status = main(["run", str(GATES / "mission_swarm.py"), "--plain", "--output", str(out)])
    err = capsys.readouterr().err
    assert "mission_swarm.py flies 2 drones (cf0, cf1), where its world spawns them, as a fleet" in err
    assert status == 1 and err.count("ScriptExit: the script exited with status 1") >= 1  # its shutdown_all()
    config = GATES / "sim_config" / "world_swarm.json"
    for drone, spawn in (("cf0", (0.0, 0.0)), ("cf1", (0.0, 3.0))):  # cf1 spawns 3 m north of cf0 in the config
        log = [json.loads(line) for line in (out / drone / "events.jsonl").read_text().splitlines()]
        states = [r for r in log if r["kind"] == "state"]
        assert tuple(states[0]["position"][:2]) == spawn
        flying = [r for r in states if r["landed_state"] == "in_air"]
        for name, (center, yaw) in gates(config).items():
            passes = crossings(flying, center, yaw, 0.8)
            assert len(passes) == 2 and all(d < 0.3 for d in passes), (drone, name, passes)
        assert [r["kind"] for r in log].count("drone_landed") == 1


def test_a_literal_point_in_a_frame_of_the_world_is_checked_where_it_lies():
    """Before flight, a point given in one of the world's frames is placed by it and checked there: 1 m before
    gate_0 is inside the field; 200 m along gate_0's x axis (south, the gate turned -1.57 rad) is beyond its bounds.
    A frame the world does not place is refused, naming the world's."""
    world = mission_world(GATES / "mission.py")
    header = "from as2_python_api.drone_interface import DroneInterface\nuav = DroneInterface('cf0')\n" \
             "uav.arm()\nuav.offboard()\nuav.takeoff(2.0, 0.7)\n"

    def problems(call: str) -> list[str]:
        found = check_mission_source(header + call + "\nuav.land(0.5)\n", "mission.py", world=world)
        return [p.message for p in found]

    assert problems("uav.go_to.go_to_point([1.0, 0.0, 0.8], 1.0, frame_id='gate_0/link')") == []
    far = problems("uav.go_to.go_to_point([200.0, 0.0, 0.8], 1.0, frame_id='gate_0/link')")
    assert len(far) == 1 and "(-0.84, -198.5, 0.8) is outside the world's bounds" in far[0], far
    unknown = problems("uav.go_to.go_to_point([1.0, 0.0, 0.8], 1.0, frame_id='gate_7/link')")
    assert unknown == ["The frame 'gate_7/link' of go_to.go_to_point() is not correct: aeroexec flies in the earth "
                       "frame (local ENU from home) nor one of the world's (gate_0/link, gate_1/link); other frames "
                       "of ROS 2's tf tree are not available (this mission uses ROS 2 beyond the drone interface)"]


def test_a_broken_world_config_is_named_and_its_frames_are_refused(tmp_path, capsys, caplog):
    # a project's world config that does not parse, and one whose gate has no pose: each is said, naming the file
    # (and the object), and the frames they would have placed are refused before flight, as unknown frames are
    project = tmp_path / "project"
    shutil.copytree(GATES, project)
    (project / "sim_config" / "world_swarm.json").unlink()  # the swarm's config would be taken in its place
    config = project / "sim_config" / "world.json"
    good = config.read_text()
    config.write_text(good.replace('"objects"', '"objects" :', 1))
    flight = fly(project / "mission.py", tmp_path / "broken", capsys, world_file=None)
    assert flight.status == 1 and flight.records == []
    assert "names frames of ROS 2's tf tree" in flight.err
    assert any("world.json is not read as the project's simulation world" in r.getMessage()
               and "line" in r.getMessage() for r in caplog.records)
    caplog.clear()
    data = json.loads(good)
    next(o for o in data["objects"] if o["model_name"] == "gate_1").pop("xyz")
    config.write_text(json.dumps(data))
    flight = fly(project / "mission.py", tmp_path / "no-pose", capsys, world_file=None)
    assert flight.status == 1 and flight.records == []
    assert any("world.json: object 2 (gate_1) needs xyz and rpy" in r.getMessage() for r in caplog.records)
    assert "'gate_1/link' (line 195)) that are not frames of the world (gate_0/link" in flight.err
