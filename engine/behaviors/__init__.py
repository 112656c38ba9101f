"""The behavior library for aerial robots (paper Appendix A): behavior processes and capability processes."""

from __future__ import annotations

from ..process import BehaviorLibrary
from ..resources import ProcessRegistry
from .basic import Wait
from .motion import MOTION_BEHAVIORS
from .perception import PERCEPTION_BEHAVIORS, PERCEPTION_PROCESSES
from .planning import PLANNING_BEHAVIORS, PLANNING_PROCESSES


def default_library() -> BehaviorLibrary:
    """Every behavior implemented for the aerial catalog."""
    return BehaviorLibrary([*MOTION_BEHAVIORS, *PERCEPTION_BEHAVIORS, *PLANNING_BEHAVIORS, Wait])


def default_processes() -> ProcessRegistry:
    """The capability processes; names without an implementation run as idle processes."""
    return ProcessRegistry({**PERCEPTION_PROCESSES, **PLANNING_PROCESSES})


__all__ = ["default_library", "default_processes"]
