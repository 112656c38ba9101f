"""Aerostack2's ``MissionInterpreter`` over aeroexec: a loaded plan runs on the drone's engine, one item after
another, while the script polls ``status``/``current_behavior`` or waits (``perform_mission()``,
``exec_thread.join()``). Every version's calls are taken: ``MissionInterpreter(mission=...)`` with
``perform_mission()`` (of 2023: ``perform_mission(debug)``), ``load_mission(mid, mission)`` with
``start_mission(mid)`` or ``start_mission(mid, idx)``.
Like Aerostack2's, the interpreter goes on to the next item when one fails, and stops at a rejected goal.
"""

from __future__ import annotations

import logging
from typing import Any

from aeroexec.dialects.aerostack2 import behaviors as aerostack2
from aeroexec.dialects.aerostack2.as2_python_api.drone_interface_base import DroneInterfaceBase
from aeroexec.dialects.aerostack2.as2_python_api.mission_interpreter.mission import (
    InterpreterState,
    InterpreterStatus,
    Mission,
    MissionItem,
)
from aeroexec.dialects.aerostack2.behavior_runs import BehaviorQueue, BehaviorRun
from aeroexec.engine import api
from aeroexec.engine.errors import RequestRejected

logger = logging.getLogger("MissionInterpreter")


class _Execution:
    """What ``exec_thread`` is while a plan runs: ``join()`` waits for its end."""

    def __init__(self, interpreter: MissionInterpreter) -> None:
        self._interpreter = interpreter

    def join(self, timeout: float | None = None) -> None:
        queue = self._interpreter._queue
        if queue is not None:
            with api.talking_to(queue.engine):
                queue.wait()

    def is_alive(self) -> bool:
        return self._interpreter._running()


class MissionInterpreter:
    """Mission Interpreter and Executer."""

    def __init__(self, mission: Mission | None = None, use_sim_time: bool = False, verbose: bool = False,
                 executor: Any = None) -> None:
        self._missions: dict[int, Mission] = {}
        self._current_mid: int | None = None
        self._drone: DroneInterfaceBase | None = None
        self._queue: BehaviorQueue | None = None
        self._items: list[MissionItem] = []
        self.stopped = False
        if mission is not None:
            self.load_mission(0, mission)

    # -- missions ----------------------------------------------------------------------------------------
    @property
    def mission(self) -> Mission | None:
        return self._missions.get(self._current_mid)

    def load_mission(self, mid: int, mission: Mission) -> None:
        self._missions[mid] = mission
        if self._current_mid is None:
            self._current_mid = mid
        self.drone  # noqa: B018 - the drone and the plan's modules, as Aerostack2 loads them
        logger.info("Mission %s loaded", mid)

    @property
    def drone(self) -> DroneInterfaceBase | None:
        """The drone interface of the mission's target, with the modules its plan uses."""
        mission = self.mission
        if mission is None:
            return None
        if self._drone is None or self._drone.drone_id != mission.target:
            self._drone = DroneInterfaceBase(drone_id=mission.target)
        for item in mission.plan:
            self._drone.load_module(item.behavior)
        return self._drone

    # -- running -------------------------------------------------------------------------------------------
    def start_mission(self, mid: int | None = None, idx: int = 0) -> bool:
        """Start the mission (from item ``idx``) and return at once."""
        if self._running():
            logger.warning("Mission being performed, start not allowed")
            return False
        if mid is not None and mid in self._missions:
            self._current_mid = mid
        mission, drone = self.mission, self.drone
        if mission is None or drone is None:
            logger.error("Mission %s not found, please load it first", mid)
            return False
        self._items = list(mission.plan)
        with api.talking_to(drone.engine):
            self._queue = BehaviorQueue(drone.engine, [self._runs(drone, item) for item in self._items])
            self._queue.start(idx)
        return True

    def _runs(self, drone: DroneInterfaceBase, item: MissionItem) -> list[BehaviorRun] | None:
        """The behavior runs of one item; None when its goal is rejected (the interpreter stops there)."""
        try:
            call = aerostack2.method(item.behavior, item.method)
            requests = aerostack2.requests(call, call.bind((), item.args), home=drone.telemetry().home,
                                           frames=drone.world_frames)
            return [BehaviorRun(r.behavior, **r.arguments) for r in requests]
        except aerostack2.As2Error as error:
            drone.refuse(f"{item.behavior}.{item.method}", error.kind, error.message)
        except RequestRejected as rejected:
            logger.error("Goal rejected by behavior %s: %s", item.behavior, rejected.message)
        return None

    def perform_mission(self, debug: bool | None = None) -> None:
        """Run the mission to its end. ``debug`` is the interpreter's of March to May 2023 (until as2_python_api
        265d4722): unless it was True, the interpreter armed the drone and switched it to offboard first; since,
        the script does (the call has no ``debug``)."""
        if debug is False and self.drone is not None:
            self.drone.arm()
            self.drone.offboard()
        if self.start_mission():
            self.exec_thread.join()

    def _running(self) -> bool:
        if self._queue is None:
            return False
        with api.talking_to(self._queue.engine):
            return not self._queue.state()[1]

    @property
    def exec_thread(self) -> _Execution | bool:
        """Falsy when no mission runs (as Aerostack2's, which is False then)."""
        return _Execution(self) if self._running() else False

    def _position(self) -> tuple[int, bool]:
        if self._queue is None:
            return -1, True
        with api.talking_to(self._queue.engine):
            return self._queue.state()

    @property
    def current_behavior(self) -> Any:
        """The module of the item running now (None when none runs)."""
        index, finished = self._position()
        if finished or not 0 <= index < len(self._items) or self._drone is None:
            return None
        return self._drone.modules.get(self._items[index].behavior)

    @property
    def status(self) -> InterpreterStatus:
        index, finished = self._position()
        if self._queue is None:
            return InterpreterStatus(pending_items=len(self.mission.plan) if self.mission else 0)
        if finished:
            return InterpreterStatus(done_items=len(self._items))
        return InterpreterStatus(InterpreterState.RUNNING, len(self._items) - index - 1, index, self._items[index])

    @property
    def feedback(self) -> Any:
        behavior = self.current_behavior
        return None if behavior is None else behavior.feedback

    feedback_dict = feedback

    def stop_mission(self, mid: int | None = None) -> bool:
        self.stopped = True
        if self._queue is not None:
            with api.talking_to(self._queue.engine):
                self._queue.stop()
        return True

    def next_item(self, mid: int | None = None) -> bool:
        if not self._running():
            logger.warning("No mission being executed, next item not allowed")
            return False
        with api.talking_to(self._queue.engine):
            self._queue.skip()
        return True

    def pause_mission(self, mid: int | None = None) -> bool:
        logger.warning("pausing the interpreter is not supported here (aeroexec ctl pause pauses the run)")
        return False

    resume_mission = pause_mission

    def shutdown(self) -> None:
        """Shutdown properly (the plan is left to run to its end, as Aerostack2 joins its thread)."""
        if self._running():
            self.exec_thread.join()
        if self._drone is not None:
            self._drone.shutdown()
        logger.info("Shutdown")
