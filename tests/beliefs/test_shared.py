"""Beliefs several memories share (beliefs/shared.py): each memory answers from its own beliefs first, then from the
shared rows it does not hide; rules read them too, and see them change."""

import pytest
from aeroexec.beliefs import BeliefMemory
from aeroexec.beliefs.shared import SharedBeliefs


@pytest.mark.parametrize("rules_first", [False, True])
def test_rules_read_shared_beliefs_and_follow_their_changes(rules_first):
    where = SharedBeliefs("position", 2)
    where.put(("d2", (1.0, 2.0, 3.0)))
    memory = BeliefMemory()
    memory.add("position(self, (0.0, 0.0, 0.0))")
    if not rules_first:
        memory.share(where.view(hidden=(("d1",),)))
    memory.add_rules("mate(?o) :- position(?o, ?p), ?o != self.")
    if rules_first:
        memory.share(where.view(hidden=(("d1",),)))
    assert memory.query_all("mate(?o)") == [{"?o": "d2"}]
    where.put(("d3", (4.0, 0.0, 0.0)))
    where.put(("d1", (9.0, 9.0, 9.0)))  # the memory's own drone: hidden from it
    assert memory.query_all("mate(?o)") == [{"?o": "d2"}, {"?o": "d3"}]
    assert memory.query("position(d3, ?p)") == {"?p": (4.0, 0.0, 0.0)}
    where.drop(("d2",))
    assert memory.query_all("mate(?o)") == [{"?o": "d3"}]
    memory.add("position(d3, (5.0, 5.0, 5.0))")  # what a memory knows itself comes before what it shares
    assert memory.query_all("position(d3, ?p)") == [{"?p": (5.0, 5.0, 5.0)}]
    assert {str(b) for b in memory.beliefs("position")} == {"position(self, (0.0, 0.0, 0.0))",
                                                            "position(d3, (5.0, 5.0, 5.0))"}  # what it stores
