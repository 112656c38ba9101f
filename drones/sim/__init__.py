"""The simulated drone and its world: kinematics on an external clock, obstacles, markers, camera."""

from aeroexec.drones.sim.airspace import Airspace
from aeroexec.drones.sim.camera import Camera
from aeroexec.drones.sim.config import SimConfig
from aeroexec.drones.sim.drone import SimulatedDrone
from aeroexec.drones.sim.world import World, WorldError
from aeroexec.drones.sim.world_file import default_world, load_world

__all__ = ["Airspace", "Camera", "SimConfig", "SimulatedDrone", "World", "WorldError", "default_world", "load_world"]
