"""A resumed run against a MAVLink vehicle (``aeroexec sim``'s simulated drone, as PX4 and as ArduPilot) through
MAVSDK: the run stops while the vehicle flies (the process crashes; the vehicle holds where the autopilot leaves
it), the resume reconnects, sees the vehicle armed and in the air, and rejoins from there: no take-off, no landing
first; the mission goes on and every goal is achieved once."""

from __future__ import annotations

import math
import threading

import pytest
from aeroexec.drones.interface import LandedState
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from free_ports import free_udp_port
from journeys import MISSIONS, achieved, active, crash, fly_until, resume, spec

pytestmark = pytest.mark.mavsdk

SPEED = 6.0  # simulated seconds per wall second


class Watch:
    """The vehicle's landed state, looked at every 20 ms of wall time while a run flies."""

    def __init__(self, vehicle: MavlinkVehicle) -> None:
        self.vehicle, self.states = vehicle, []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._look, daemon=True)

    def _look(self) -> None:
        while not self._stop.wait(0.02):
            self.states.append(self.vehicle.telemetry().landed_state)

    def __enter__(self) -> Watch:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_a_resumed_run_rejoins_a_vehicle_still_in_the_air_without_landing(tmp_path, autopilot):
    port = free_udp_port()
    vehicle = MavlinkVehicle(SimulatedDrone(), connect=f"udpout://127.0.0.1:{port}", speed=SPEED, autopilot=autopilot)
    vehicle.start()
    try:
        folder = tmp_path / "run"
        drone = f"mavsdk:udpin://127.0.0.1:{port}"
        crash(fly_until(spec(MISSIONS / "figure10.py", folder, drone=drone, ready_timeout=60.0),
                        active("GO_TO_POINT", 0.2)))
        flying = vehicle.telemetry()
        assert flying.armed and flying.landed_state == LandedState.IN_AIR  # the crash left it flying
        with Watch(vehicle) as watch:
            session, outcome = resume(folder, ready_timeout=60.0)
        assert outcome.exit_status == 0, outcome.status
        events = session.engine.log.events()
        assert not [e for e in events if e.kind == "activated" and e.behavior == "TAKE_OFF"]
        landed = watch.states.index(LandedState.ON_GROUND) if LandedState.ON_GROUND in watch.states else None
        goal_land = next(e for e in events if e.kind == "activated" and e.behavior == "LAND")
        assert landed is not None and all(s != LandedState.ON_GROUND for s in watch.states[:landed])
        assert goal_land.data["source"] == "mission"  # it came down only for the mission's own LAND
        assert [b for b, _ in achieved(folder)] == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
        end = vehicle.telemetry()
        assert end.landed_state == LandedState.ON_GROUND and math.dist(end.position[:2], (0.0, 0.0)) < 1.5
    finally:
        vehicle.stop()
