"""The contact checks' broad phase (the platform's path box, the objects' grid columns) answers exactly as
measuring every object and the platform at every substep: a seeded random walk weaving around the objects and
over the platform's path, with the broad phase and without it."""

import math
import random

from aeroexec.drones.sim.vehicle.contact import DECK_CONTACT, Contacts
from aeroexec.drones.sim.world import Bounds, Platform, World, WorldObject

OBJECTS = (WorldObject("ball", "red", "sphere", (3.0, 0.0, 0.4)), WorldObject("box", "blue", "cube", (-4.1, 3.9, 1.0)),
           WorldObject("cone", "green", "cone", (8.0, 8.0, 0.0)), WorldObject("crate", "red", "cube", (7.6, 8.3, 0.6)))
PLATFORM = Platform("cart", ((0.0, -3.0, 0.5), (6.0, -3.0, 0.5), (6.0, 2.0, 0.8)), speed=0.7, loop=True)
WORLD = World(home=(47.0, 8.0, 400.0), bounds=Bounds((-30.0, -30.0, 0.0), (30.0, 30.0, 20.0)), objects=OBJECTS,
              platform=PLATFORM)


def deck_measured(position, t, previous_z):
    """``Contacts.deck_below`` without a broad phase."""
    cx, cy, cz = PLATFORM.position(t)
    if math.hypot(position[0] - cx, position[1] - cy) > PLATFORM.deck_radius:
        return None
    return cz if previous_z >= cz - DECK_CONTACT else None


def test_the_broad_phase_finds_the_same_touches_and_decks_as_measuring_everything():
    rng = random.Random(7)
    indexed, measured = Contacts(WORLD, 0.5), Contacts(WORLD, 0.5)
    measured._indexed = False  # measure every object and the platform, in the world's order
    targets = [o.position for o in OBJECTS] + [PLATFORM.path[0], PLATFORM.path[2], (0.0, 0.0, 3.0)]
    position, touches, decks = (0.0, 0.0, 1.0), 0, 0
    for step in range(20000):
        t = step * 0.02
        if step % 150 == 0:
            target = rng.choice(targets)
        heading = [(g - p) * 0.05 + rng.gauss(0.0, 0.08) for g, p in zip(target, position, strict=True)]
        previous_z = position[2]
        position = (position[0] + heading[0], position[1] + heading[1], max(position[2] + heading[2], 0.0))
        found = indexed.touches(position, t)
        assert found == measured.touches(position, t), f"step {step} at {position}"
        assert indexed.touching == measured.touching
        deck = indexed.deck_below(position, t, previous_z)
        assert deck == deck_measured(position, t, previous_z)
        touches += len(found)
        decks += deck is not None
    assert touches > 20 and decks > 20  # the walk did come near things and over the deck


def test_shared_names_are_measured_without_the_broad_phase():
    other = WorldObject("ball", "red", "sphere", (9.0, 0.0, 0.4))
    twins = World(home=WORLD.home, bounds=WORLD.bounds, objects=(OBJECTS[0], other))
    contacts = Contacts(twins, 0.5)
    assert not contacts._indexed
    assert contacts.touches((9.0, 0.0, 0.5), 0.0) == [("ball", (9.0, 0.0, 0.4))]
