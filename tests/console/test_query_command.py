"""The operator's belief query (the console's query box, ``aeroexec ctl query``): every unification, read-only."""

from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine


def make_engine():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    engine.step(0.2)
    return engine


def test_a_query_answers_every_unification_and_is_not_an_operator_command():
    engine = make_engine()
    engine.memory.declare("seen", 2)
    for n in range(3):
        engine.memory.add(f"seen(marker_{n}, aruco)")
    result = engine.supervisor.execute("query", "seen(?M, aruco)")
    assert result.ok and result.data["count"] == 3
    assert sorted(a["?M"] for a in result.data["answers"]) == ["marker_0", "marker_1", "marker_2"]
    assert not engine.log.events(kind="operator_command")


def test_a_broken_expression_is_refused_in_the_papers_words():
    result = make_engine().supervisor.execute("query", "seen(?M,")
    assert not result.ok and "The format of the belief expression" in result.message
