"""The behavior library for aerial robots (paper Appendix A): behavior processes and capability processes."""

from __future__ import annotations

from aeroexec.engine.behaviors.basic import Wait
from aeroexec.engine.behaviors.communication import COMMUNICATION_BEHAVIORS, COMMUNICATION_PROCESSES
from aeroexec.engine.behaviors.localization import LOCALIZATION_BEHAVIORS, LOCALIZATION_PROCESSES
from aeroexec.engine.behaviors.motion import MOTION_BEHAVIORS
from aeroexec.engine.behaviors.perception import PERCEPTION_BEHAVIORS, PERCEPTION_PROCESSES
from aeroexec.engine.behaviors.planning import PLANNING_BEHAVIORS, PLANNING_PROCESSES
from aeroexec.engine.behaviors.recording import RECORDING_BEHAVIORS, RECORDING_PROCESSES
from aeroexec.engine.behaviors.targets import TARGET_BEHAVIORS, TARGET_PROCESSES
from aeroexec.engine.behaviors.verify import VERIFY_BEHAVIORS
from aeroexec.engine.execution.process import BehaviorLibrary
from aeroexec.engine.execution.resources import ProcessRegistry


def aerial_behaviors() -> BehaviorLibrary:
    """Every behavior implemented for the aerial catalog."""
    return BehaviorLibrary([*MOTION_BEHAVIORS, *PERCEPTION_BEHAVIORS, *COMMUNICATION_BEHAVIORS, *PLANNING_BEHAVIORS,
                            *LOCALIZATION_BEHAVIORS, *VERIFY_BEHAVIORS, *TARGET_BEHAVIORS, *RECORDING_BEHAVIORS, Wait])


def aerial_processes() -> ProcessRegistry:
    """The capability processes; names without an implementation run as idle processes."""
    return ProcessRegistry({**PERCEPTION_PROCESSES, **COMMUNICATION_PROCESSES, **PLANNING_PROCESSES,
                            **LOCALIZATION_PROCESSES, **TARGET_PROCESSES, **RECORDING_PROCESSES})


__all__ = ["aerial_behaviors", "aerial_processes"]
