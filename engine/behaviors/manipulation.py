"""Configuration and manipulation (paper Table A.3): TURN_LIGHTS and DROP_ITEM.

TURN_LIGHTS keeps the light's state as the belief ``light(self, on|off)`` (the drone interface has no lights to
switch; the catalog's light state machine checks plans). DROP_ITEM opens the drone's payload release and
retracts ``carry(self, X)`` for the item that left; the telemetry updater writes ``carry`` from what the drone
says it carries. Their capability processes (``light_controller``, ``gripper_controller``) are idle: the work is
one drone command or one belief.
"""

from __future__ import annotations

import logging

from aeroexec.beliefs import Struct
from aeroexec.drones import CommandHandle, Failure
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess, Situation

logger = logging.getLogger(__name__)


class TurnLights(BehaviorProcess):
    """TURN_LIGHTS: MODE=ON or OFF becomes ``light(self, on|off)``; already so is a goal already achieved."""

    behavior = "TURN_LIGHTS"

    @property
    def wanted(self) -> str:
        return str(self.arguments["MODE"]).lower()

    def check_situation(self) -> Situation | None:
        if self.memory.holds(Struct("light", ("self", self.wanted))):
            return Situation(Outcome.GOAL_ACHIEVED, f"the lights are already {self.wanted}")
        return None

    def on_start(self) -> None:
        self.memory.add(Struct("light", ("self", self.wanted)))
        self.result = self.wanted
        self.context.log.record("lights", self.name, f"lights {self.wanted}")

    def on_run(self) -> Outcome | None:
        return Outcome.GOAL_ACHIEVED


class DropItem(BehaviorProcess):
    """DROP_ITEM: release the payload; ``carry(self, X)`` is retracted for what left. Result: the item's name."""

    behavior = "DROP_ITEM"

    def on_start(self) -> None:
        self._before = list(self.drone.payload())
        found = self.memory.query("carry(self, ?item)")
        self._item = found["?item"] if found else (self._before[0] if self._before else None)
        try:
            self._handle = self.drone.release_payload()
        except Exception as exc:  # a failing adapter is a failed drop, not a crashed engine
            logger.exception("release_payload failed")
            self._handle = CommandHandle.failed("release_payload", Failure.DENIED, f"it raised {exc}")

    def on_run(self) -> Outcome | None:
        handle = self._handle
        if not handle.done:
            if self.elapsed >= self.settings.command_timeout:
                return self.fail(f"the payload release did not answer in {self.settings.command_timeout:g} s")
            return None
        if not handle.ok:
            return self.fail(handle.reason or "the payload release failed")
        after = set(self.drone.payload())
        dropped = [i for i in self._before if i not in after] if self._before else [self._item]
        for item in dropped:
            if item is not None:
                self.memory.remove(Struct("carry", ("self", item)))
        self.result = dropped[0] if dropped else self._item
        self.context.log.record("item_dropped", self.name, f"{self.result} dropped at "
                                f"{tuple(round(v, 1) for v in self.telemetry().position)}", item=self.result)
        return Outcome.GOAL_ACHIEVED


MANIPULATION_BEHAVIORS: list[type[BehaviorProcess]] = [TurnLights, DropItem]
MANIPULATION_PROCESSES: dict[str, type] = {}  # light_controller and gripper_controller run as idle processes
