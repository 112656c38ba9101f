"""Aerostack2's ``BehaviorHandler`` over aeroexec: what every behavior module offers (``status``, ``result``,
``stop()``, ``wait_to_result()``...), each request a catalog behavior run on the drone's engine."""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from aeroexec.dialects.aerostack2.as2_msgs.msg import BehaviorStatus
from aeroexec.dialects.aerostack2.behavior_runs import BehaviorRun
from aeroexec.dialects.aerostack2.behaviors import Request
from aeroexec.engine import api
from aeroexec.engine.errors import RequestRejected
from aeroexec.engine.events import Outcome

if TYPE_CHECKING:
    from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase

logger = logging.getLogger(__name__)

#: action_msgs/msg/GoalStatus codes, as ``result_status`` gives them.
STATUS_UNKNOWN, STATUS_SUCCEEDED, STATUS_CANCELED, STATUS_ABORTED = 0, 4, 5, 6


class BehaviorHandler:
    """A behavior of one drone: started by its module's methods, then waited for, polled or stopped."""

    TIMEOUT = 1  # seconds (Aerostack2 waits this long for a behavior server; here the engine is always there)

    class BehaviorNotAvailable(Exception):
        """Behavior not available exception."""

    class GoalRejected(Exception):
        """Goal rejected exception."""

    class ResultUnknown(Exception):
        """Result unknown exception."""

    def __init__(self, drone: DroneInterfaceBase, *args: Any, **kwargs: Any) -> None:
        self._drone = drone
        self._runs: list[BehaviorRun] = []

    @property
    def _run(self) -> BehaviorRun | None:
        return self._runs[-1] if self._runs else None

    def _perform(self, requests: Sequence[Request]) -> bool:
        """Run the requests one after the other (all but the last to their end); True when the last succeeded,
        or, not waited for, was accepted."""
        with api.talking_to(self._drone.engine):
            for index, request in enumerate(requests):
                try:
                    run = BehaviorRun(request.behavior, **request.arguments)
                except RequestRejected as rejected:  # recorded as refused; Aerostack2's goal rejection is False
                    logger.debug("%s: goal rejected: %s", self._drone.drone_id, rejected.message)
                    return False
                self._runs = [run]
                last = index == len(requests) - 1
                if last and not request.wait:  # accepted, or achieved already (the drone is there)
                    return run.start() or run.outcome is Outcome.GOAL_ACHIEVED
                if run.wait() is not Outcome.GOAL_ACHIEVED:
                    return False
        return True

    @property
    def status(self) -> int:
        """RUNNING while the behavior runs, IDLE otherwise (a call to the engine: polling lets time move)."""
        run = self._run
        if run is None:
            return BehaviorStatus.IDLE
        with api.talking_to(self._drone.engine):
            return BehaviorStatus.RUNNING if run.running() else BehaviorStatus.IDLE

    def is_running(self) -> bool:
        return self.status == BehaviorStatus.RUNNING

    @property
    def feedback(self) -> dict[str, Any] | None:
        """While the behavior runs: the drone's speed and position (Aerostack2's feedback message's gist)."""
        if not self.is_running():
            return None
        return {"actual_speed": self._drone.speed, "position": self._drone.position}

    @property
    def result_status(self) -> int:
        run = self._run
        if run is None or run.outcome is None:
            return STATUS_UNKNOWN
        if run.outcome is Outcome.GOAL_ACHIEVED:
            return STATUS_SUCCEEDED
        return STATUS_CANCELED if run.outcome is Outcome.INTERRUPTED else STATUS_ABORTED

    @property
    def result(self) -> bool:
        """True when the last request succeeded, False when it failed; ResultUnknown while it runs."""
        if self.result_status == STATUS_UNKNOWN:
            raise self.ResultUnknown("Result not received yet")
        return self.result_status == STATUS_SUCCEEDED

    def wait_to_result(self) -> bool:
        """Wait until the behavior ends: True when it succeeded."""
        run = self._run
        if run is None:
            return False
        with api.talking_to(self._drone.engine):
            return run.wait() is Outcome.GOAL_ACHIEVED

    def stop(self) -> bool:
        """Stop the behavior (INTERRUPTED); True when it is not running any more."""
        run = self._run
        if run is None:
            return True
        with api.talking_to(self._drone.engine):
            run.stop("stopped by the mission")
        return True

    def pause(self) -> bool:
        logger.warning("%s: pausing one behavior is not supported (aeroexec ctl pause pauses the mission)",
                       self._drone.drone_id)
        return False

    def resume(self, wait_result: bool = True) -> bool:
        return self.pause()

    def modify(self, *args: Any, **kwargs: Any) -> bool:
        logger.warning("%s: modifying a running behavior is not supported", self._drone.drone_id)
        return False

    def destroy(self) -> None:
        """Nothing to release: the behavior keeps running on the drone, as in Aerostack2."""
