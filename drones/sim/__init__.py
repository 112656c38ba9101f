"""The simulated drone and its world: kinematics on an external clock, obstacles, markers, camera.

Each name is imported from its module when first used (``aeroexec.lazy``): a world is read without the drone.
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["Airspace", "Camera", "SimConfig", "SimulatedDrone", "World", "WorldError", "default_world", "load_world"]
__getattr__ = lazy_names(__name__, {"Airspace": "airspace", "Camera": "camera", "SimConfig": "config",
                                    "SimulatedDrone": "drone", "World": "world", "WorldError": "world",
                                    "default_world": "world_file", "load_world": "world_file"})

if TYPE_CHECKING:
    from aeroexec.drones.sim.airspace import Airspace
    from aeroexec.drones.sim.camera import Camera
    from aeroexec.drones.sim.config import SimConfig
    from aeroexec.drones.sim.drone import SimulatedDrone
    from aeroexec.drones.sim.world import World, WorldError
    from aeroexec.drones.sim.world_file import default_world, load_world
