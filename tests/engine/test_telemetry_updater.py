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


def heard_in_a_flight(always_write: bool) -> list[tuple]:
    """Every belief change of a take-off, a flight to a point and a landing, with a belief retracted and one
    overwritten by someone else on the way; ``always_write``: the updater forgets what it wrote before each update,
    so it writes every value (the memory answering whether it changed): the slow path its comparisons skip."""
    from aeroexec.engine.execution.updaters import TelemetryUpdater

    engine = Engine(SimulatedDrone(seed=4))
    updater = next(u for u in engine.updaters if isinstance(u, TelemetryUpdater))
    if always_write:
        update = updater.update

        def forgetting(memory, now):
            updater._written.clear()
            update(memory, now)

        updater.update = forgetting
    heard = []
    engine.memory.subscribe(lambda c: heard.append((c.kind, str(c.belief), c.reason, c.time)))
    engine.step(0.5)
    for name, arguments in (("TAKE_OFF", {"ALTITUDE": 3}), ("GO_TO_POINT", {"COORDINATES": [4.0, -2.0, 3.0]})):
        assert engine.coordinator.activate(name, arguments).accepted
        engine.run_until(lambda n=name: n not in engine.coordinator.active(), 60.0)
        engine.memory.remove("flight_state(self, ?S)")  # retracted by someone: written again
        engine.memory.add("speed(self, 42.0)")  # overwritten by someone: written again
        engine.step(0.3)
    assert engine.coordinator.activate("LAND", {}).accepted
    engine.run_until(lambda: "LAND" not in engine.coordinator.active(), 60.0)
    return heard


def test_the_telemetry_beliefs_skipped_as_unchanged_are_those_writing_them_would_not_change():
    fast = heard_in_a_flight(always_write=False)
    assert any(b.startswith("position(self") for _, b, _, _ in fast) and any(
        b == "speed(self, 42.0)" and kind == "removed" for kind, b, _, _ in fast), "the flight tests nothing"
    assert fast == heard_in_a_flight(always_write=True)
