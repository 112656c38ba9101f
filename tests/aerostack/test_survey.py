"""The held-back survey's verdicts (tools/aerostack2_survey.py) are read from each run's event logs: a flight to
completion is checked there, for a run that exits 0 too, and a flight that completed and then ended by the
script's own non-zero exit is a verdict of its own, counted apart."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

TOOL = Path(__file__).parents[2] / "tools" / "aerostack2_survey.py"

FLIGHT = """import sys
import rclpy
from as2_python_api.drone_interface import DroneInterface

rclpy.init()
uav = DroneInterface("drone0")
uav.arm()
uav.offboard()
uav.takeoff(2.0, 1.0)
uav.go_to(2.0, 0.0, 2.0, 1.0)
uav.land(0.5)
uav.shutdown()
rclpy.shutdown()
{end}
"""
LEDS = """import rclpy
from as2_python_api.drone_interface import DroneInterface
from std_msgs.msg import ColorRGBA

rclpy.init()
uav = DroneInterface("drone0")
leds = uav.create_publisher(ColorRGBA, "leds/control", 10)
leds.publish(ColorRGBA(r=1.0))
uav.shutdown()
"""


@pytest.fixture(scope="module")
def survey():
    spec = importlib.util.spec_from_file_location("aerostack2_survey", TOOL)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules[spec.name]


def outcome(survey, tmp_path, name, source):
    project = tmp_path / "owner__project"
    project.mkdir(exist_ok=True)
    (project / name).write_text(source)
    return survey.fly(project / name, 120.0, project)


@pytest.mark.parametrize("end, verdict, status", [("sys.exit(0)", "flew", 0), ("", "flew", 0),
                                                  ("sys.exit(2)", "flew, then exited 2", 1)])
def test_a_flight_to_completion_and_the_scripts_own_exit_after_it(survey, tmp_path, end, verdict, status):
    """The run of a script that exits 2 after its flight fails (status 1, the script's ScriptExit its reason); the
    survey tells it from a failure in flight by the run's event log."""
    found = outcome(survey, tmp_path, "mission.py", FLIGHT.format(end=end))
    assert (found.file, found.verdict, found.status) == ("owner__project/mission.py", verdict, status), found
    if status:
        assert found.reason == "landed and disarmed, then the script's own exit: sys.exit(2)"


def test_a_run_that_ends_0_without_flying_is_no_flight_to_completion(survey, tmp_path):
    """challenge_multi_drone's LED test: status 0, and nothing flew."""
    found = outcome(survey, tmp_path, "leds.py", LEDS)
    assert (found.verdict, found.status, found.reason) == ("incomplete", 0, "the drone never took off")


def test_a_failure_in_flight_is_not_a_flight_then_an_exit(survey, tmp_path):
    source = FLIGHT.format(end="").replace("uav.land(0.5)", "raise SystemExit(4)")
    found = outcome(survey, tmp_path, "crash.py", source)
    assert (found.verdict, found.status) == ("failed", 1), found  # it exited in the air (the run landed it)
    assert found.reason == "crash.py: ScriptExit: the script exited with status 4"


def test_the_figures_are_printed_apart(survey, capsys):
    outcomes = [survey.Outcome("a.py", "flew", 0, ""), survey.Outcome("b.py", "flew, then exited 1", 1, "x"),
                survey.Outcome("c.py", "refused", 1, "y")]
    survey.report(outcomes)
    assert capsys.readouterr().out.splitlines()[-1] == (
        "flew to completion: 1 of 3; flew to completion, then exited non-zero by the script's own exit: 1 of 3; "
        "flew what it asked, then left the drone in the air (the run landed it): 0 of 3")


def test_a_script_that_ends_with_the_drone_flying_did_not_fly_to_completion(survey, tmp_path):
    """project_landing's mission.py takes off and ends (its run and landing commented out): under python3 the drone
    is left hovering; aeroexec's run lands it, which is not the mission's landing."""
    found = outcome(survey, tmp_path, "hover.py", FLIGHT.format(end="").replace("uav.land(0.5)", "pass"))
    assert (found.verdict, found.status, found.reason) == (
        "flew, left in the air", 0, "the mission ended with the drone in the air (the run landed it)")
