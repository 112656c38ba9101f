"""Fixtures of the console and Groot2 tests: a tree mission on the simulator."""

import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.trees import read_mission_tree
from aeroexec.trees.runtime.runner import TreeMission
from console_helpers import TREE


@pytest.fixture
def tree_mission():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    mission = TreeMission(read_mission_tree(TREE, "groot_test.xml"), engine, name="groot_test")
    yield mission
    engine.stop()
