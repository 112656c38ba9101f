"""Behaviors that do not move the drone: WAIT."""

from __future__ import annotations

from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorProcess


class Wait(BehaviorProcess):
    """WAIT: a number of seconds (DURATION), or until a visual marker is observed (UNTIL_OBSERVED_VISUAL_MARKER)."""

    behavior = "WAIT"

    def on_run(self) -> Outcome | None:
        duration = self.arguments.get("DURATION")
        if duration is not None:
            return Outcome.GOAL_ACHIEVED if self.elapsed >= duration - 1e-9 else None
        marker = self.arguments.get("UNTIL_OBSERVED_VISUAL_MARKER")
        if self.memory.holds("code(?M, ?WANTED), visible(?M)", {"?WANTED": marker}):
            return Outcome.GOAL_ACHIEVED
        return None
