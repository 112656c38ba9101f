"""The aeroexec rover: aeroexec's execution engine embedded in a differential-drive ground robot.

Everything here uses aeroexec's public API only; ``aeroexec run MISSION --robot rover`` finds it through the
entry point ``rover`` in the group ``aeroexec.robots`` (this package's pyproject.toml).
"""

from __future__ import annotations

from pathlib import Path

from aeroexec.engine import EngineSettings, ProcessRegistry, RobotKind
from aeroexec.engine.behaviors import aerial_processes

from aeroexec_rover.behaviors import rover_behaviors
from aeroexec_rover.rover import RoverConfig, SimulatedRover
from aeroexec_rover.updaters import RoverUpdater

HERE = Path(__file__).parent
CATALOG = HERE / "rover_catalog.yaml"
YARD = HERE / "yard.yaml"


def rover_processes() -> ProcessRegistry:
    """The marker detector and the speech synthesizer are aeroexec's; the wheel controller is the rover itself."""
    aerial = aerial_processes().factories()
    return ProcessRegistry({name: aerial[name] for name in ("aruco_detector", "speech_synthesizer")})


def simulated_rover(world, seed: int = 0) -> SimulatedRover:
    """A rover docked at the yard's dock, charged as ``AEROEXEC_ROVER_BATTERY`` says (percent, default 100)."""
    import os

    battery = float(os.environ.get("AEROEXEC_ROVER_BATTERY", "100"))
    dock = next((o.position for o in world.objects if o.name == "dock"), (0.0, 0.0, 0.0))
    return SimulatedRover(world, config=RoverConfig(battery=battery), start=(dock[0], dock[1]), heading=0.0)


def robot_kind() -> RobotKind:
    """The rover, as ``aeroexec run --robot rover`` uses it."""
    return RobotKind(name="rover", description="a differential-drive ground rover with a charging dock",
                     catalog=CATALOG, behaviors=rover_behaviors, processes=rover_processes,
                     simulator=simulated_rover, telemetry=RoverUpdater, world=YARD,
                     settings=lambda: EngineSettings(hold_behavior="KEEP_STILL", cruise_speed=0.8))


__all__ = ["RoverConfig", "RoverUpdater", "SimulatedRover", "robot_kind", "rover_behaviors", "rover_processes"]
