"""Aerostack (Sirocco, ROS 1) missions: an import of a ROS module the mission never uses is a warning and the
mission flies (a use is refused at its line); a mission asking again and again for a refused behavior lets time
pass, a tick per request, and its identical refusals are recorded once with a count."""

from __future__ import annotations

import textwrap

from flying import SIROCCO, fly

WARNING = ("rospy is imported but never used: the mission runs without it (a use would be refused: this mission "
           "uses ROS beyond Aerostack's mission API)")


def test_sirocco_missions_importing_rospy_without_using_it_fly(tmp_path, capsys):
    flight = fly(SIROCCO / "teleoperation_pixhawk_mission.py", tmp_path, capsys, world_file=None)
    assert flight.status == 0, flight.err
    assert f"teleoperation_pixhawk_mission.py:4:1: warning: {WARNING}" in flight.err
    assert flight.achieved() == ["TAKE_OFF", "FOLLOW_PATH", "LAND"]
    assert "Finish mission..." in flight.out
    other = fly(SIROCCO / "tfg_mission.py", tmp_path, capsys, world_file=None)
    assert other.status == 0, other.err  # it ends in the air: the run lands the drone
    assert other.achieved() == ["TAKE_OFF", "FOLLOW_PATH", "LAND"]


def test_sirocco_missions_are_refused_for_their_behaviors_not_for_rospy(tmp_path, capsys):
    flight = fly(SIROCCO / "bridge_inspection_mission1.py", tmp_path, capsys, world_file=None)
    assert flight.status == 1 and not flight.records
    assert "error: WRONG_FORMAT: The behavior INFORM_POSITION_TO_ROBOTS does not exist" in flight.err
    assert f"warning: {WARNING}" in flight.err and "rospy" not in flight.err.replace(WARNING, "")


def test_a_use_of_rospy_fails_the_mission_at_its_line(tmp_path, capsys):
    path = tmp_path / "uses.py"
    path.write_text(textwrap.dedent("""\
        import mission_execution_control as mxc

        def mission():
            mxc.executeTask('TAKE_OFF')
            rospy = __import__("ros" + "py")  # computed: verify cannot see it
            rospy.sleep(2)
        """))
    flight = fly(path, tmp_path, capsys, world_file=None)
    assert flight.status == 1
    assert "uses.py at uses.py:6: RosFeatureError: rospy.sleep: this mission uses ROS beyond Aerostack's mission " \
           "API" in flight.kinds("mission_failed")[0]["detail"]


def test_polling_a_refused_behavior_lets_time_pass_and_says_each_refusal_once_with_a_count(tmp_path, capsys):
    path = tmp_path / "polling.py"  # ours, after the wiki missions that poll on once the drone has landed
    path.write_text(textwrap.dedent("""\
        import executive_engine_api as api

        def runMission():
            api.executeBehavior('TAKE_OFF')
            api.executeBehavior('LAND')  # as the low-battery reaction lands it
            while api.executeBehavior('GO_TO_POINT', coordinates=[4, -4, 3]) != 'GOAL_ACHIEVED':
                pass
        """))
    flight = fly(path, tmp_path, capsys, "--max-time", "300", world_file=None)
    assert flight.status == 1 and flight.kinds("run_ended")
    end = flight.kinds("run_ended")[-1]["time"]
    assert end >= 300.0  # the time limit was reached: simulated time did not crawl
    refusals = [r for r in flight.kinds("failed_preconditions") if r["behavior"] == "GO_TO_POINT"]
    said = [r for r in refusals if "repeated" not in r["data"]]
    counted = [r["data"]["repeated"] for r in refusals if "repeated" in r["data"]]
    assert len(said) <= 3 and counted  # each distinct refusal said once, then counted
    # at least a tick per refused request: no more requests than ticks in 300 s at 20 Hz
    assert len(said) + sum(counted) <= 300 * 20
    lines = [line for line in flight.out.splitlines() if "failed_preconditions GO_TO_POINT" in line]
    assert len(lines) == len(refusals) < 20 and any("the same refusal" in line for line in lines)


def test_polling_for_a_belief_after_a_refused_behavior_ends_soon_with_the_reason(tmp_path, capsys):
    path = tmp_path / "search.py"  # ours, after the missions that search for object_1 in a loop
    path.write_text(textwrap.dedent("""\
        import executive_engine_api as api

        def runMission():
            api.executeBehavior('TAKE_OFF')
            api.executeBehavior('LAND')  # as a low-battery reaction lands it
            while not api.trueBelief('visible(object_1)'):
                api.activateBehavior('GO_TO_POINT', coordinates=[4, -4, 3])  # refused: the drone is landed
                while not api.trueBelief('visible(object_1)'):
                    pass
        """))
    flight = fly(path, tmp_path, capsys, world_file=None)
    assert flight.status == 1
    failed = flight.kinds("mission_failed")
    assert failed and "MissionStalled: the mission polls for something nothing is doing: its request GO_TO_POINT" \
                      in failed[0]["detail"] and "was refused, and none of its behaviors runs" in failed[0]["detail"]
    assert flight.kinds("run_ended")[-1]["time"] < 60.0  # not the 1,800 s time limit
    states = [r for r in flight.records if r["kind"] == "state"]
    assert states[-1]["landed_state"] == "on_ground"


def test_a_sirocco_task_that_ends_without_its_goal_fails_the_run(tmp_path, capsys):
    path = tmp_path / "path_task.py"  # ours: a FOLLOW_PATH task that cannot end in time; the mission goes on
    path.write_text(textwrap.dedent("""\
        import mission_execution_control as mxc

        def mission():
            mxc.executeTask('TAKE_OFF')
            mxc.executeTask('FOLLOW_PATH', path=[[0, 0, 2], [10, 0, 2]], timeout=1)
            mxc.executeTask('LAND')
        """))
    flight = fly(path, tmp_path, capsys, world_file=None)
    assert flight.status == 1, flight.err  # was 0: completed
    ended = flight.kinds("run_ended")[-1]
    assert ended["detail"] == "failed"
    assert "FOLLOW_PATH ended with TIME_OUT" in " ".join(ended["data"]["reasons"])
    assert [r["behavior"] for r in flight.kinds("GOAL_ACHIEVED")][-1] == "LAND"  # the mission went on and landed
