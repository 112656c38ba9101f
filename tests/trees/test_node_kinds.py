"""The node kinds are one table of descriptors (issue 41, ``trees/runtime/kinds.py``): every pass asks the kind, so
the words a kind may say are the words the passes know, a kind that says another is refused where it is made, and
each built-in kind's class is the one the table names."""

from __future__ import annotations

import pytest
from aeroexec.trees.runtime.kinds import BUILT_IN, FLOWS, ROUTES, NodeKind, kind_of
from aeroexec.trees.runtime.manifests import MANIFESTS, InputPort, action
from aeroexec.trees.sequence_check import SequenceChecker


def test_the_sequence_check_knows_every_flow_a_kind_may_say():
    assert set(SequenceChecker.flows) == set(FLOWS)
    assert {kind.flow for kind in BUILT_IN} <= set(FLOWS) and {kind.route for kind in BUILT_IN} <= set(ROUTES)


def test_a_kind_with_a_flow_or_route_no_pass_knows_is_refused_naming_it():
    with pytest.raises(ValueError, match="the node kind Beep: flow 'sequnce' is none of sequence, "):
        NodeKind("Beep", action(), "toy:Beep", flow="sequnce")
    with pytest.raises(ValueError, match="the node kind Beep: route 'fly' is none of series, repeat, parallel"):
        NodeKind("Beep", action(InputPort("times")), "toy:Beep", route="fly")


def test_each_built_in_kind_names_the_class_that_takes_its_manifest():
    assert [kind.name for kind in BUILT_IN] == list(MANIFESTS)
    assert [k.name for k in BUILT_IN if k.node_class().manifest is not MANIFESTS[k.name]] == []
    assert kind_of("Parallel").counts_children == ("success_count", "failure_count")
    assert kind_of("SubTree").subtree and not kind_of("Sequence").subtree
    assert kind_of("GO_TO_POINT") is None  # a catalog behavior is no node kind
