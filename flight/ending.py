"""The end of a flight: reach the drone again if its link is down (for a grace time, while the autopilot's own
failsafe acts), land it if it is in the air, confirm it disarmed, and say what went wrong.

A safety rule's contingency in effect when the mission ends that the table of contingencies says to finish first
(``hold``, ``return``: ``finish_before_landing``) is never undone by the end: the drone first finishes the
contingency's flight (to where the rule last held, or to the return point), then a hold lands where it holds and a
return lands where it returned.

:class:`FlightEnding` does this one engine period at a time, so one run (:func:`end_flight`) and a fleet of
drones in lockstep end their flights the same way. A run whose link was lost in flight, whose final landing
failed, or that leaves the drone armed or in the air has faults (:func:`flight_faults`), sentences for the run's
last line; a link lost on the ground before the mission started is a warning, not a fault.
"""

from __future__ import annotations

import logging
import math

from aeroexec.drones import Drone, LandedState
from aeroexec.engine.catalog.contingencies import contingency_kinds
from aeroexec.engine.supervision.supervisor import LAND_BEHAVIOR, LANDING_TIMEOUT, is_flying, start_landing
from aeroexec.flight.spec import LINK_GRACE

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

DISARM_TIMEOUT = 10.0  # s to wait for the drone to disarm on the ground (on its own, then by command)
_AUTO_DISARM = 3.0  # s autopilots take to disarm on their own after touchdown before we command it
_LOSSES = 3  # links lost during the final landing that are waited for again
#: A safety rule's hold or return ends where the drone has stopped: it lands once its horizontal speed is below
#: this (m/s), or after :data:`_SETTLE_TIME` s; stopped farther than :data:`_OFF_TARGET` m from where the rule holds
#: it (a boundary crossed at speed), it is flown back there once first.
_SETTLED_SPEED = 0.3
_SETTLE_TIME = 10.0
_OFF_TARGET = 1.0
_LANDING_FAILED = ("WRONG_PROGRESS", "TIME_OUT", "FAILED_PRECONDITIONS", "failed_preconditions", "rejected")
LINK, LAND, DISARM, DONE = "link", "land", "disarm", "done"


class FlightEnding:
    """The end of one engine's flight, advanced by :meth:`step` once per engine period (on the thread that
    drives the loop) until it returns True; then :attr:`faults` says what went wrong."""

    def __init__(self, engine: Any, *, link_grace: float = LINK_GRACE, landing_timeout: float = LANDING_TIMEOUT,
                 disarm_timeout: float = DISARM_TIMEOUT, reason: str = "the mission ended with the drone in the air"
                 ) -> None:
        self.engine, self.reason = engine, reason
        self.link_grace, self.landing_timeout, self.disarm_timeout = link_grace, landing_timeout, disarm_timeout
        self.phase = LINK
        self.faults: list[str] = []
        self._since = engine.now()  # when the current phase began
        self._losses = 0
        self._waiting = False  # the link wait was announced
        self._landing = False  # LAND was asked for
        self._disarm: Any = None  # the disarm command, once sent
        self._held = False  # the contingency in effect was announced
        self._settling: float | None = None  # when the drone began to stop where a contingency holds it
        self._flown_back = False  # a drone stopped off the contingency's target was flown back to it
        flight = contingency_flight(engine)
        self._contingency_time = 0.0 if flight is None or flight.timeout is None else max(
            0.0, flight.started_at + flight.timeout - engine.now())  # s its flight may still take
        engine.bridge.close()
        supervisor = getattr(engine, "supervisor", None)
        if supervisor is not None:
            supervisor.flight_ending = True  # a pause now would stop the landing: refused

    @property
    def done(self) -> bool:
        return self.phase == DONE

    @property
    def deadline(self) -> float:
        """Engine seconds the whole ending may take at most (for a loop that drives it)."""
        return (self.link_grace + self.landing_timeout) * _LOSSES + _AUTO_DISARM + self.disarm_timeout + 1.0 + \
            2 * self._contingency_time + 2 * _SETTLE_TIME

    def step(self) -> bool:
        """Advance by what the last engine period brought; True once the flight has ended."""
        if self.phase == LINK:
            self._wait_for_link()
        if self.phase == LAND:
            self._land()
        if self.phase == DISARM:
            self._confirm_disarm()
        if self.phase == DONE and not self.faults:
            self.faults = flight_faults(self.engine)
        return self.phase == DONE

    def _enter(self, phase: str) -> None:
        self.phase, self._since = phase, self.engine.now()

    def _elapsed(self) -> float:
        return self.engine.now() - self._since

    def _link_ok(self) -> bool:
        return self.engine.drone.telemetry().link_ok

    def _wait_for_link(self) -> None:
        log = self.engine.log
        if self._link_ok():
            if self._waiting:
                log.record("link_back", detail=f"the drone answers again at t={self.engine.now():.1f} s")
                self._waiting = False
            self._enter(LAND)
            return
        if not self._waiting:
            self._waiting = True
            log.record("waiting_for_link", detail=f"the link to the drone is down: trying to reach it for "
                                                  f"{self.link_grace:g} s (its own failsafe acts meanwhile)")
        if self._elapsed() >= self.link_grace - 1e-9:
            log.record("link_not_back", detail=f"no answer from the drone within {self.link_grace:g} s")
            self._enter(DONE)

    def _land(self) -> None:
        engine = self.engine
        landing = engine.coordinator.is_active(LAND_BEHAVIOR)
        if not self._landing:
            if not is_flying(engine) and not landing:
                self._landed()
                return
            rule = contingency_in_effect(engine)
            if rule is not None and not landing:
                if not self._held:
                    self._held = True
                    engine.log.record("ending_held", detail=f"the mission ended while safety rule {rule.name} "
                                                            f"({rule.contingency}) is in effect: the drone finishes it "
                                                            f"and lands where it {_lands_where(rule)}",
                                      rule=rule.name, contingency=str(rule.contingency))
                if contingency_flight(engine) is not None:
                    return  # still flying to where the rule holds it (its own timeout bounds the wait)
                if self._settled(rule):
                    return  # stopping where the rule holds it, or flown back there
            self._landing = True
            self._since = engine.now()  # the landing's time from now, after a contingency's flight
            start_landing(engine, self.reason if rule is None else
                          f"the mission ended; safety rule {rule.name} ({rule.contingency}): landing where it "
                          f"{_lands_where(rule)}")
            return
        still = landing or (is_flying(engine) and engine.drone.telemetry().landed_state is LandedState.LANDING)
        if still and self._elapsed() < self.landing_timeout:
            return  # still landing
        if not is_flying(engine):
            self._landed()
        elif not self._link_ok() and self._losses + 1 < _LOSSES:  # the link dropped during the landing
            self._losses += 1
            self._landing = False
            self._enter(LINK)
        else:
            self._enter(DONE)

    def _settled(self, rule: Any) -> bool:
        """Whether the ending still waits for the drone to stop where ``rule``'s contingency holds it (True), its
        speed and its distance to the contingency's target checked once per period."""
        engine = self.engine
        if self._settling is None:
            self._settling = engine.now()
        telemetry = engine.drone.telemetry()
        if math.hypot(*telemetry.velocity[:2]) > _SETTLED_SPEED and engine.now() - self._settling < _SETTLE_TIME:
            return True
        contingencies = engine.safety.contingencies
        target = contingencies.target
        if not self._flown_back and target is not None and math.dist(telemetry.position, target) > _OFF_TARGET:
            self._flown_back, self._settling = True, None
            engine.log.record("ending_held", detail=f"the drone stopped {math.dist(telemetry.position, target):.1f} m "
                                                    f"from where safety rule {rule.name} holds it: flown back there "
                                                    f"before it lands", rule=rule.name,
                              contingency=str(rule.contingency))
            contingencies.take_again()
            return True
        return False

    def _landed(self) -> None:
        if self._link_ok() and isinstance(self.engine.drone, Drone):
            self._enter(DISARM)
        else:
            self._enter(DONE)

    def _confirm_disarm(self) -> None:
        """On the ground and still armed: wait for the autopilot to disarm on its own, else disarm it."""
        engine = self.engine
        telemetry = engine.drone.telemetry()
        if not telemetry.armed or is_flying(engine):
            self._enter(DONE)
            return
        if self._disarm is None:
            if self._elapsed() < min(_AUTO_DISARM, self.disarm_timeout):
                return
            engine.log.record("disarming", detail="the drone is on the ground and still armed")
            self._disarm = engine.drone.disarm()
            self._since = engine.now()
            return
        if self._disarm.done and not self._disarm.ok or self._elapsed() >= self.disarm_timeout:
            logger.warning("the drone did not disarm: %s", self._disarm.reason if self._disarm.done else "no answer")
            self._enter(DONE)


def _lands_where(rule: Any) -> str:
    """Where the drone lands once ``rule``'s contingency is finished, in words: "holds", "returned"."""
    kind = contingency_kinds().get(rule.contingency.kind)
    return kind.lands_where if kind is not None and kind.lands_where else "is"


def contingency_in_effect(engine: Any) -> Any:
    """The safety rule in effect whose contingency the end of the mission finishes before landing (a ``hold``, a
    ``return``: the table's ``finish_before_landing``); None when none is."""
    safety = getattr(engine, "safety", None)
    rule = safety.contingencies.active if safety is not None else None
    kind = contingency_kinds().get(rule.contingency.kind) if rule is not None else None
    return rule if kind is not None and kind.finish_before_landing else None


def contingency_flight(engine: Any) -> Any:
    """The activation of a safety contingency's flight under way (to where a rule holds, or back), else None."""
    if contingency_in_effect(engine) is None:
        return None
    return next((a for a in engine.coordinator.active().values()
                 if a.source == "safety" and a.name != LAND_BEHAVIOR and a.category != "recurrent"), None)


def end_flight(engine: Any, *, link_grace: float = LINK_GRACE, landing_timeout: float = LANDING_TIMEOUT,
               disarm_timeout: float = DISARM_TIMEOUT, reason: str = "the mission ended with the drone in the air"
               ) -> list[str]:
    """Bring one engine's flight to a safe end on the thread that drives its loop, after the mission; the faults
    (empty when the drone is on the ground, disarmed, and the link never dropped in flight)."""
    ending = FlightEnding(engine, link_grace=link_grace, landing_timeout=landing_timeout,
                          disarm_timeout=disarm_timeout, reason=reason)
    engine.run_until(ending.step, ending.deadline)
    if not ending.done:  # the engine was stopped meanwhile
        ending.phase = DONE
        ending.faults = flight_faults(engine)
    engine.tick()  # the log hears what the drone just reported (disarmed)
    return ending.faults


def flight_faults(engine: Any) -> list[str]:
    """What went wrong with the vehicle during the run, in words: link losses in flight or during the mission, a
    failed final landing, a drone left in the air or armed. A loss on the ground before the mission started is
    recorded as a warning (``link_warning``), not a fault."""
    faults = []
    events = engine.log.events()
    started = next((e.time for e in events if e.kind == "mission_started"), None)
    for i, event in enumerate(events):
        if event.kind != "drone_link_lost":
            continue
        data = event.data
        back = next((e for e in events[i + 1:] if e.kind == "drone_link_restored"), None)
        before = started is None or event.time < started
        if before and not data.get("in_air") and (back is not None and (started is None or back.time <= started)):
            continue  # a drop on the ground before the mission, over before it began: warned of when it happened
        where = "with the drone in the air" if data.get("in_air") else "with the drone on the ground"
        if data.get("in_air") and data.get("altitude") is not None:
            where += f" at {data['altitude']:.1f} m"
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


__all__ = ["DISARM_TIMEOUT", "FlightEnding", "contingency_flight", "contingency_in_effect", "end_flight",
           "flight_faults"]
