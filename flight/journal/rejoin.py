"""Putting the drone back where an interrupted mission left it, before the mission goes on.

The mission stopped with the drone at some place, flying or not (the journal's ``stop``, or its last state after a
crash); the drone is now where it is (on the ground after a battery swap, still hovering after a crash of the
companion computer). When it was flying and the behavior under way does not need the ground:

- on the ground now: TAKE_OFF to the height it flew at, then GO_TO_POINT back to the place;
- in the air now (a real vehicle that held its position, or drifted): GO_TO_POINT back, when farther than
  :data:`NEAR` (m); nothing when it is there already: no landing first;
- in the air now with a GO_TO_POINT under way (a real vehicle flies on to its target after the companion computer
  is killed): nothing: the leg starts again toward its target from where the drone is, not from where the
  journal last saw it.

A TAKE_OFF under way whose drone is in the air now climbs to the TAKE_OFF's height (its goal is then reached, and
said so); a LAND under way whose drone is on the ground now has reached its goal. These behaviors run with the
source ``resume`` (they are not the mission's goals) and the engine's timeouts; one that does not reach its goal
ends the rejoin with the reason, and the mission does not go on.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from aeroexec.drones import LandedState
from aeroexec.engine.catalog.engine_behaviors import GO_TO_POINT, TAKE_OFF
from aeroexec.engine.events import Outcome

logger = logging.getLogger(__name__)

NEAR = 1.0  # m: a drone this close to where the mission left it is there
KNOWN = 15.0  # s of engine time a vehicle may take to say where it is (landed state; armed when in the air)
LOWEST, HIGHEST = 0.5, 50.0  # m: the take-off heights the catalog allows
#: Landed states of a drone in the air (landing too: it is still up there).
FLYING = (LandedState.IN_AIR.value, LandedState.TAKING_OFF.value, LandedState.LANDING.value)


@dataclass
class Rejoin:
    """The steps back to ``place`` (ENU m) for ``engine``'s drone. ``was_flying``: the drone flew when the mission
    stopped; ``under_way``: the mission's behaviors under way then, with their arguments. :meth:`start` runs the
    steps (on the engine's thread); ``done(None)`` once the drone is back, ``done(reason)`` when it cannot be."""

    engine: Any
    place: tuple[float, float, float]
    was_flying: bool
    under_way: dict[str, dict[str, Any]] = field(default_factory=dict)
    settled: list[tuple[str, str]] = field(default_factory=list)  # (behavior, why its goal is reached)
    flies_on: bool = False  # a leg under way goes on from where the drone is (no flight back first)
    _steps: list[tuple[str, dict[str, Any]]] = field(default_factory=list)
    _done: Callable[[str | None], None] | None = None
    _until: float = 0.0

    def plan(self) -> list[tuple[str, dict[str, Any]]]:
        """The behaviors to run, with their arguments (also the under-way goals reached: :attr:`settled`)."""
        telemetry = self.engine.drone.telemetry()
        flying = telemetry.landed_state.value in FLYING
        catalog = self.engine.catalog
        steps: list[tuple[str, dict[str, Any]]] = []
        x, y, z = self.place
        # the behaviors under way that land or take off, and those that fly and climb: the catalog's motions
        landing = next((n for n in self.under_way if catalog.motion_of(n) == "descend"), None)
        taking_off = next((n for n in self.under_way if catalog.motion_of(n) == "climb"), None)
        fly, climb = catalog.with_motion("fly_to", GO_TO_POINT), catalog.with_motion("climb", TAKE_OFF)
        if landing is not None and not flying:
            self.settled.append((landing, "the drone is on the ground"))
        elif taking_off is not None and flying:
            height = float(self.under_way[taking_off].get("ALTITUDE") or max(z, LOWEST))
            here = telemetry.position
            if abs(here[2] - height) > NEAR / 2:
                steps.append((fly, {"COORDINATES": (here[0], here[1], height)}))
            self.settled.append((taking_off, f"the drone flies at {height:g} m"))
        elif self.was_flying and taking_off is None and landing is None:
            if not flying:
                steps.append((climb, {"ALTITUDE": min(HIGHEST, max(LOWEST, round(z, 2)))}))
            if flying and any(catalog.motion_of(name) == "fly_to" for name in self.under_way):
                # a leg under way, the drone still in the air (a real vehicle flew on after the crash): the leg
                # goes on toward its target from where the drone is, never back to where the journal last saw it
                self.flies_on = True
            elif not flying or math.dist(telemetry.position, self.place) > NEAR:
                steps.append((fly, {"COORDINATES": (round(x, 3), round(y, 3), round(z, 3))}))
        return [(name, arguments) for name, arguments in steps if name in catalog]

    def start(self, done: Callable[[str | None], None]) -> None:
        """Run the steps (on the engine's thread) once the vehicle has said where it is (a MAVSDK vehicle just
        reconnected tells its landed state and arming a moment later); ``done`` hears how it went."""
        self._done = done
        self._until = self.engine.now() + KNOWN
        if self._known():
            self._go()
        else:
            self.engine.tick_callbacks.append(self._wait)

    def _known(self) -> bool:
        telemetry = self.engine.drone.telemetry()
        return telemetry.landed_state is not LandedState.UNKNOWN and (
            telemetry.landed_state is LandedState.ON_GROUND or telemetry.armed)

    def _wait(self) -> None:
        if not self._known() and self.engine.now() < self._until:
            return
        self.engine.tick_callbacks.remove(self._wait)
        if self._known():
            self._go()
        else:
            self._finish(f"the vehicle did not say where it is (landed or flying, armed) within {KNOWN:g} s")

    def _go(self) -> None:
        self._steps = self.plan()
        if self.flies_on:
            x, y, z = self.engine.drone.telemetry().position
            self.engine.log.record("rejoin", detail=f"the drone is in the air at ({x:.1f}, {y:.1f}, {z:.1f}): the leg "
                                                    f"under way goes on toward its target from there",
                                   place=list(self.place), steps=[])
        if self._steps:
            where = ", ".join(f"{name} {tuple(args.values())[0]}" for name, args in self._steps)
            self.engine.log.record("rejoin", detail=f"back to where the mission stopped: {where}",
                                   place=list(self.place), steps=[name for name, _ in self._steps])
        self._next()

    def _next(self) -> None:
        if not self._steps:
            self._finish(None)
            return
        name, arguments = self._steps.pop(0)
        result = self.engine.coordinator.activate(name, arguments, source="resume", on_end=self._ended,
                                                  check_preconditions=self.engine.catalog.motion_of(name) != "fly_to")
        if result.accepted:
            return
        if result.outcome is Outcome.GOAL_ACHIEVED:  # there already
            self._next()
        else:
            self._finish(f"{name} could not start: {result.message}")

    def _ended(self, outcome: Outcome, message: str, _value: Any) -> None:
        if outcome is Outcome.GOAL_ACHIEVED:
            self._next()
        else:
            self._finish(f"{outcome.value}: {message}")

    def _finish(self, reason: str | None) -> None:
        done, self._done = self._done, None
        if done is not None:
            done(reason)


__all__ = ["NEAR", "Rejoin"]
