"""The end of a flight: reach the drone again if its link is down (for a grace time, while the autopilot's own
failsafe acts), land it if it is in the air, confirm it disarmed, and say what went wrong.

A run whose link was lost, whose final landing failed, or that leaves the drone armed or in the air has
faults; :func:`end_flight` returns them as sentences for the run's last line.
"""

from __future__ import annotations

import logging
from typing import Any

from aeroexec.drones import Drone
from aeroexec.engine.supervision.supervisor import LAND_BEHAVIOR, LANDING_TIMEOUT, is_flying, land_if_flying

logger = logging.getLogger(__name__)

LINK_GRACE = 30.0  # s of engine time the engine keeps trying to reach a drone whose link is down
DISARM_TIMEOUT = 10.0  # s to wait for the drone to disarm on the ground (on its own, then by command)
_AUTO_DISARM = 3.0  # s autopilots take to disarm on their own after touchdown before we command it
_LOSSES = 3  # links lost during the final landing that are waited for again
_LANDING_FAILED = ("WRONG_PROGRESS", "TIME_OUT", "FAILED_PRECONDITIONS", "failed_preconditions", "rejected")


def end_flight(engine: Any, *, link_grace: float = LINK_GRACE, landing_timeout: float = LANDING_TIMEOUT,
               disarm_timeout: float = DISARM_TIMEOUT) -> list[str]:
    """Bring the flight to a safe end on the thread that drives the engine loop, after the mission; the faults
    (empty when the drone is on the ground, disarmed, and the link never dropped)."""
    landed = False
    for _ in range(_LOSSES):
        if not wait_for_link(engine, link_grace):
            break
        landed = land_if_flying(engine, landing_timeout)
        if landed or engine.drone.telemetry().link_ok:
            break  # on the ground, or the landing failed for another reason than the link
    if landed and engine.drone.telemetry().link_ok and isinstance(engine.drone, Drone):
        confirm_disarm(engine, disarm_timeout)
        engine.tick()  # the log hears what the drone just reported (disarmed)
    return flight_faults(engine)


def wait_for_link(engine: Any, grace: float) -> bool:
    """Tick the engine until the drone's link is back or ``grace`` seconds pass; True when it is up."""
    if engine.drone.telemetry().link_ok:
        return True
    engine.log.record("waiting_for_link", detail=f"the link to the drone is down: trying to reach it for "
                                                 f"{grace:g} s (its own failsafe acts meanwhile)")
    if engine.run_until(lambda: engine.drone.telemetry().link_ok, grace):
        engine.log.record("link_back", detail=f"the drone answers again at t={engine.now():.1f} s")
        return True
    engine.log.record("link_not_back", detail=f"no answer from the drone within {grace:g} s")
    return False


def confirm_disarm(engine: Any, timeout: float = DISARM_TIMEOUT) -> bool:
    """On the ground and still armed: wait for the autopilot to disarm on its own, else disarm it; True once
    its telemetry says disarmed."""
    def disarmed() -> bool:
        return not engine.drone.telemetry().armed

    if disarmed() or is_flying(engine):
        return disarmed()
    if engine.run_until(disarmed, min(_AUTO_DISARM, timeout)):
        return True
    engine.log.record("disarming", detail="the drone is on the ground and still armed")
    handle = engine.drone.disarm()
    if engine.run_until(lambda: disarmed() or (handle.done and not handle.ok), timeout) and disarmed():
        return True
    logger.warning("the drone did not disarm: %s", handle.reason if handle.done else "no answer")
    return False


def flight_faults(engine: Any) -> list[str]:
    """What went wrong with the vehicle during the run, in words: link losses, a failed final landing, a drone
    left in the air or armed."""
    faults = []
    events = engine.log.events()
    for i, event in enumerate(events):
        if event.kind != "drone_link_lost":
            continue
        data = event.data
        where = "with the drone in the air" if data.get("in_air") else "with the drone on the ground"
        if data.get("in_air") and data.get("altitude") is not None:
            where += f" at {data['altitude']:.1f} m"
        back = next((e for e in events[i + 1:] if e.kind == "drone_link_restored"), None)
        faults.append(f"link lost at t={event.time:.1f} s {where}" +
                      (f" (back at t={back.time:.1f} s)" if back is not None else ""))
    telemetry = engine.drone.telemetry()
    if not telemetry.link_ok:
        if not faults:
            faults.append("the link to the drone is down")
        faults.append("the drone did not answer again: its state is unknown")
        return faults
    landing = [e for e in events if e.behavior == LAND_BEHAVIOR and e.kind in _LANDING_FAILED]
    if is_flying(engine):
        why = f" (landing failed: {landing[-1].detail or landing[-1].kind})" if landing else ""
        faults.append(f"the drone was left in the air at {telemetry.position[2]:.1f} m{why}")
    elif telemetry.armed and isinstance(engine.drone, Drone):  # a robot of another kind has no motors to arm
        faults.append("the drone was left armed on the ground")
    return faults
