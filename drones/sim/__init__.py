"""The simulated drone and its world: kinematics on an external clock, obstacles, markers, camera."""

from .camera import Camera
from .config import SimConfig
from .drone import SimulatedDrone
from .world import World, WorldError, default_world, load_world

__all__ = ["Camera", "SimConfig", "SimulatedDrone", "World", "WorldError", "default_world", "load_world"]
