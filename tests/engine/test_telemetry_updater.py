"""The telemetry belief updater writes the drone's own beliefs only when they change."""

from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.engine import Engine


def test_telemetry_beliefs_are_written_when_they_change_and_again_after_a_removal():
    engine = Engine(SimulatedDrone())
    engine.step(0.5)
    added = []
    engine.memory.subscribe(lambda change: added.append(str(change.belief)) if change.kind == "added" else None)
    engine.step(1.0)  # on the ground, nothing changes: nothing is written again
    assert not [b for b in added if b.startswith(("flight_state", "armed", "position"))]
    engine.memory.remove("flight_state(self, ?S)")
    engine.step(0.2)
    assert engine.memory.query("flight_state(self, landed)") is not None  # written again after its removal
