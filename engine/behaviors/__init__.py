"""The behavior library for aerial robots (paper Appendix A): behavior processes and capability processes."""

from __future__ import annotations

from ..process import BehaviorLibrary
from ..resources import ProcessRegistry
from .basic import Wait
from .communication import COMMUNICATION_BEHAVIORS, COMMUNICATION_PROCESSES
from .localization import LOCALIZATION_BEHAVIORS, LOCALIZATION_PROCESSES
from .motion import MOTION_BEHAVIORS
from .perception import PERCEPTION_BEHAVIORS, PERCEPTION_PROCESSES
from .planning import PLANNING_BEHAVIORS, PLANNING_PROCESSES
from .recording import RECORDING_BEHAVIORS, RECORDING_PROCESSES
from .targets import TARGET_BEHAVIORS, TARGET_PROCESSES
from .verify import VERIFY_BEHAVIORS


def default_library() -> BehaviorLibrary:
    """Every behavior implemented for the aerial catalog."""
    return BehaviorLibrary([*MOTION_BEHAVIORS, *PERCEPTION_BEHAVIORS, *COMMUNICATION_BEHAVIORS, *PLANNING_BEHAVIORS,
                            *LOCALIZATION_BEHAVIORS, *VERIFY_BEHAVIORS, *TARGET_BEHAVIORS, *RECORDING_BEHAVIORS, Wait])


def default_processes() -> ProcessRegistry:
    """The capability processes; names without an implementation run as idle processes."""
    return ProcessRegistry({**PERCEPTION_PROCESSES, **COMMUNICATION_PROCESSES, **PLANNING_PROCESSES,
                            **LOCALIZATION_PROCESSES, **TARGET_PROCESSES, **RECORDING_PROCESSES})


__all__ = ["default_library", "default_processes"]
