"""The real mission files of ``data/real_missions`` (SOURCES.md says where each comes from), what aeroexec must make
of each (fly it, or refuse it at an item and why), and flying one in the simulator as ``aeroexec run`` does."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.engine import Engine
from aeroexec.flight.missions import CheckedMission, check_mission
from aeroexec.trees.mission_world import mission_world
from aeroexec.trees.runtime.runner import TreeMission

DATA = Path(__file__).with_name("data") / "real_missions"
FILES = sorted(p for p in DATA.glob("*/*") if p.name != "SOURCES.md")


@dataclass(frozen=True)
class Refused:
    """A file verify refuses: the item number its first error names (None: the whole file) and what it says."""

    item: int | None
    reason: str


#: Every real file that does not fly, and why (a file that is not here flies).
REFUSED = {
    "ardupilot/DO_CHANGE_SPEED_mission.txt": Refused(4, "The value 15 of argument SPEED for behavior GO_TO_POINT is "
                                                       "not correct (a number between 0.1 and 12 is expected)"),
    "ardupilot/KSFO-VTOL.txt": Refused(1, "NAV_VTOL_TAKEOFF is a VTOL item"),
    "ardupilot/aux_functions.txt": Refused(2, "DO_AUX_FUNCTION switches an RC auxiliary function of the autopilot"),
    "ardupilot/copter_payload_place.txt": Refused(3, "NAV_PAYLOAD_PLACE lowers a payload until it touches the "
                                                     "ground: aeroexec's drone has no winch"),
    "dronekit/mpmission.txt": Refused(5, "The value (315.978, 602.397, 22222.0) of argument COORDINATES"),
    "fence_test/mission.waypoints": Refused(1, "is a geofence vertex: the file holds a geofence, not a mission"),
    "flight_energy_simulation/test_munich_flight.plan": Refused(None, "the plan was made for a VTOL (vehicleType 20)"),
    "mavsdk/qgroundcontrol_sample_with_survey_wrong_version.plan": Refused(2, "a survey of version 9: "
                                                                              "QGroundControl writes versions 3 to 5"),
    "mavsdk/qgroundcontrol_sample_without_mission.plan": Refused(None, "the plan has no \"mission\": nothing to fly"),
    "mavsdk/qgroundcontrol_sample_wrong_mission_version.plan": Refused(None, "a plan's mission of version 7: "
                                                                             "QGroundControl writes version 2"),
    "mavsdk/qgroundcontrol_sample_wrong_overall_version.plan": Refused(None, "a plan of version 42: QGroundControl "
                                                                             "writes version 1"),
    "px4/FW_mission_1.plan": Refused(None, "the plan was made for a fixed-wing aircraft (vehicleType 1)"),
    "px4/VTOL_TAKEOFF.mission": Refused(1, "NAV_VTOL_TAKEOFF is a VTOL item"),
    "qgroundcontrol/ArduPilotSITL-ArduCopter.plan": Refused(6, "the battery runs down to its 7% failsafe here: the "
                                                               "route (21.9 km, 42 min) needs 277% of a full "
                                                               "battery, 177% more than the drone has"),
    "qgroundcontrol/ce_geofence_home_base.plan": Refused(None, "the mission has no items: nothing to fly"),
    "uas_lol/mission11.waypoints": Refused(1, "NAV_VTOL_TAKEOFF is a VTOL item"),
}


def name(path: Path) -> str:
    return f"{path.parent.name}/{path.name}"


def checked(path: Path, world=None) -> CheckedMission:
    """The file verified as ``aeroexec verify`` does it, in the world ``aeroexec run`` flies it in."""
    return check_mission(path, default_catalog(), world if world is not None else mission_world(path))


def fly(path: Path, folder: Path, max_time: float = 3600.0):
    """Fly the file on the simulated clock as ``aeroexec run`` does: the tree's end status, the engine's events and
    the world it flew in."""
    world = mission_world(path)
    mission = checked(path, world)
    assert not mission.errors, [str(p) for p in mission.errors]
    engine = Engine(SimulatedDrone(world), obstacles=world, output_dir=folder)
    try:
        runner = TreeMission(mission.tree, engine)
        status = runner.run(max_time)
        return status, list(engine.log.events()), world, mission
    finally:
        engine.stop()
