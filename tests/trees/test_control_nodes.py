"""Control nodes and decorators against BehaviorTree.CPP v4's documented semantics, with scripted leaves."""

from __future__ import annotations

from types import SimpleNamespace

import py_trees
import pytest
from aeroexec.trees.runtime.nodes.branches import IfThenElse, WhileDoElse
from aeroexec.trees.runtime.nodes.controls import (
    Fallback,
    ReactiveFallback,
    ReactiveSequence,
    Sequence,
    SequenceWithMemory,
)
from aeroexec.trees.runtime.nodes.decorators import (
    Delay,
    ForceFailure,
    ForceSuccess,
    Inverter,
    KeepRunningUntilFailure,
    Repeat,
    RetryUntilSuccessful,
    RunOnce,
    Timeout,
)
from aeroexec.trees.runtime.nodes.node_conditions import NodeConditions
from aeroexec.trees.runtime.nodes.parallels import Parallel
from aeroexec.trees.runtime.nodes.registry import BUILT_IN
from aeroexec.trees.runtime.ports import NodeConfig
from aeroexec.trees.runtime.ticking import status_name
from py_trees.common import Status

S, F, R = Status.SUCCESS, Status.FAILURE, Status.RUNNING


class Scripted(py_trees.behaviour.Behaviour):
    """A leaf answering the statuses of its script in turn (the last one forever); counts ticks, starts and halts."""

    def __init__(self, name: str, *script: Status) -> None:
        super().__init__(name)
        self.script = list(script)
        self.ticks = self.starts = self.halts = 0

    def initialise(self) -> None:
        self.starts += 1

    def update(self) -> Status:
        self.ticks += 1
        return self.script.pop(0) if len(self.script) > 1 else self.script[0]

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.status == Status.RUNNING:
            self.halts += 1


def tick(node: py_trees.behaviour.Behaviour, times: int = 1) -> str:
    for _ in range(times):
        node.tick_once()
    return status_name(node)


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def config(kind: str, clock: Clock | None = None, **ports: str) -> NodeConfig:
    """A node of type ``kind`` with these ports, its context's clock ``clock``."""
    return NodeConfig.of(kind, ports, context=SimpleNamespace(now=clock))


# -- sequences ---------------------------------------------------------------------------------
def test_sequence_ticks_the_running_child_again_without_the_ones_before():
    a, b, c = Scripted("a", S), Scripted("b", R, R, S), Scripted("c", S)
    sequence = Sequence("seq", [a, b, c])
    assert tick(sequence) == "RUNNING"
    assert tick(sequence) == "RUNNING"
    assert tick(sequence) == "SUCCESS"
    assert (a.ticks, b.ticks, c.ticks) == (1, 3, 1)


def test_sequence_restarts_from_the_first_child_after_a_failure():
    a, b = Scripted("a", S), Scripted("b", F, S)
    sequence = Sequence("seq", [a, b])
    assert tick(sequence) == "FAILURE"
    assert tick(sequence) == "SUCCESS"
    assert a.ticks == 2 and b.ticks == 2


def test_sequence_with_memory_ticks_the_failed_child_again_not_the_ones_before():
    a, b = Scripted("a", S), Scripted("b", F, S)
    sequence = SequenceWithMemory("seq", [a, b])
    assert tick(sequence) == "RUNNING"  # as in BT.CPP: a child done on its first tick hands control back
    assert tick(sequence) == "FAILURE"
    assert tick(sequence) == "SUCCESS"
    assert a.ticks == 1 and b.ticks == 2


def test_reactive_sequence_ticks_every_child_each_time_and_halts_the_running_one_when_a_condition_fails():
    condition, action = Scripted("battery_ok", S, S, F), Scripted("fly", R)
    sequence = ReactiveSequence("reactive", [condition, action])
    assert tick(sequence, 2) == "RUNNING"
    assert condition.ticks == 2 and action.ticks == 2 and action.starts == 1
    assert tick(sequence) == "FAILURE"
    assert action.halts == 1 and action.status == Status.INVALID


# -- fallbacks ---------------------------------------------------------------------------------
def test_fallback_ticks_the_running_child_again_and_stops_at_the_first_success():
    a, b, c = Scripted("a", F), Scripted("b", R, S), Scripted("c", S)
    fallback = Fallback("fb", [a, b, c])
    assert tick(fallback) == "RUNNING"
    assert tick(fallback) == "SUCCESS"
    assert (a.ticks, b.ticks, c.ticks) == (1, 2, 0)
    assert tick(Fallback("all fail", [Scripted("x", F), Scripted("y", F)])) == "FAILURE"


def test_reactive_fallback_lets_a_higher_priority_child_take_over_and_halts_the_running_one():
    urgent, routine = Scripted("urgent", F, F, S), Scripted("routine", R)
    fallback = ReactiveFallback("rf", [urgent, routine])
    assert tick(fallback, 2) == "RUNNING"
    assert tick(fallback) == "SUCCESS"
    assert routine.halts == 1 and urgent.ticks == 3


# -- parallel ----------------------------------------------------------------------------------
def test_parallel_by_default_needs_every_child_and_fails_at_the_first_failure_halting_the_others():
    a, b = Scripted("a", S), Scripted("b", R, R, S)
    parallel = Parallel("par", [a, b])
    assert tick(parallel) == "RUNNING"
    assert tick(parallel) == "RUNNING"
    assert tick(parallel) == "SUCCESS"
    assert a.ticks == 1  # a completed child is not ticked again
    c, d = Scripted("c", R), Scripted("d", F)
    assert tick(Parallel("par", [c, d])) == "FAILURE"
    assert c.halts == 1


def test_parallel_thresholds():
    a, b, c = Scripted("a", R, S), Scripted("b", R), Scripted("c", R)
    parallel = Parallel("one", [a, b, c], config("Parallel", success_count="1", failure_count="3"))
    assert tick(parallel) == "RUNNING"
    assert tick(parallel) == "SUCCESS"
    assert b.halts == 1 and c.halts == 1
    x, y, z = Scripted("x", F), Scripted("y", R, F), Scripted("z", R)
    parallel = Parallel("two failures", [x, y, z], config("Parallel", success_count="1", failure_count="2"))
    assert tick(parallel) == "RUNNING"  # one failure of the two allowed
    assert tick(parallel) == "FAILURE"
    assert z.halts == 1
    impossible = Parallel("cannot succeed", [Scripted("p", F), Scripted("q", R)],
                          config("Parallel", success_count="2", failure_count="2"))
    assert tick(impossible) == "FAILURE"  # two successes are no longer possible


# -- conditional nodes ------------------------------------------------------------------------------
def test_if_then_else_ticks_its_condition_once_then_the_branch():
    condition, then, other = Scripted("if", S), Scripted("then", R, S), Scripted("else", S)
    node = IfThenElse("ite", [condition, then, other])
    assert tick(node) == "RUNNING"
    assert tick(node) == "SUCCESS"
    assert condition.ticks == 1 and then.ticks == 2 and other.ticks == 0
    assert tick(IfThenElse("no else", [Scripted("if", F), Scripted("then", S)])) == "FAILURE"
    condition, then, other = Scripted("if", F), Scripted("then", S), Scripted("else", F)
    assert tick(IfThenElse("ite", [condition, then, other])) == "FAILURE" and then.ticks == 0


def test_while_do_else_checks_its_condition_every_tick_and_halts_the_branch_it_leaves():
    condition, body, other = Scripted("while", S, S, F), Scripted("do", R), Scripted("else", R)
    node = WhileDoElse("wde", [condition, body, other])
    assert tick(node, 2) == "RUNNING"
    assert tick(node) == "RUNNING"
    assert body.halts == 1 and other.ticks == 1 and condition.ticks == 3


# -- decorators ---------------------------------------------------------------------------------
def test_timeout_on_the_engine_clock_halts_its_child_and_fails():
    clock, child = Clock(), Scripted("slow", R)
    timeout = Timeout("timeout", child, config("Timeout", clock, msec="1500"))
    assert tick(timeout) == "RUNNING"
    clock.now = 1.0
    assert tick(timeout) == "RUNNING"
    clock.now = 1.5
    assert tick(timeout) == "FAILURE"
    assert child.halts == 1 and child.ticks == 2
    fast = Timeout("timeout", Scripted("fast", R, S), config("Timeout", clock, msec="1500"))
    assert tick(fast, 2) == "SUCCESS"


def test_delay_ticks_its_child_only_after_the_delay():
    clock, child = Clock(), Scripted("late", S)
    delay = Delay("delay", child, config("Delay", clock, delay_msec="2000"))
    assert tick(delay) == "RUNNING"
    clock.now = 1.9
    assert tick(delay) == "RUNNING" and child.ticks == 0
    clock.now = 2.0
    assert tick(delay) == "SUCCESS" and child.ticks == 1


def test_retry_until_successful_ticks_a_failing_child_again_up_to_num_attempts():
    child = Scripted("flaky", R, F, R, F, R, S)  # a failure starts the child again within the same tick
    retry = RetryUntilSuccessful("retry", child, config("RetryUntilSuccessful", num_attempts="3"))
    assert [tick(retry) for _ in range(4)] == ["RUNNING"] * 3 + ["SUCCESS"]
    assert child.starts == 3
    stubborn = RetryUntilSuccessful("retry", Scripted("never", R, F, R, F, R),
                                    config("RetryUntilSuccessful", num_attempts="2"))
    assert [tick(stubborn) for _ in range(3)] == ["RUNNING", "RUNNING", "FAILURE"]


def test_repeat_runs_its_child_num_cycles_times_and_stops_at_a_failure():
    child = Scripted("lap", R, S, R, S, R, S, R)  # a success starts the child again within the same tick
    repeat = Repeat("repeat", child, config("Repeat", num_cycles="3"))
    assert [tick(repeat) for _ in range(4)] == ["RUNNING"] * 3 + ["SUCCESS"]
    assert child.starts == 3
    failing = Repeat("repeat", Scripted("bad", F), config("Repeat", num_cycles="3"))
    assert tick(failing) == "FAILURE"
    instantaneous = Repeat("forever", Scripted("quick", S), config("Repeat", num_cycles="-1"))
    assert tick(instantaneous, 5) == "RUNNING"  # one cycle per tick, never spinning inside one


def test_keep_running_until_failure():
    child = Scripted("patrol", S, S, F)
    node = KeepRunningUntilFailure("keep", child)
    assert [tick(node) for _ in range(3)] == ["RUNNING", "RUNNING", "FAILURE"]


def test_run_once_then_skips():
    child = Scripted("once", S)
    once = RunOnce("once", child)
    assert tick(once) == "SUCCESS"
    assert tick(once) == "SKIPPED" and child.ticks == 1
    again = RunOnce("remembers", Scripted("bad", F), config("RunOnce", then_skip="false"))
    assert tick(again, 3) == "FAILURE"


def test_inverter_and_forced_results():
    assert tick(Inverter("not", Scripted("a", S))) == "FAILURE"
    assert tick(Inverter("not", Scripted("a", F))) == "SUCCESS"
    assert tick(Inverter("not", Scripted("a", R))) == "RUNNING"
    assert tick(ForceSuccess("ok", Scripted("a", F))) == "SUCCESS"
    assert tick(ForceFailure("ko", Scripted("a", S))) == "FAILURE"


# -- pre-conditions and SKIPPED -------------------------------------------------------------------
def test_skip_if_passes_a_node_over_in_a_sequence_and_in_a_fallback():
    skipped, after = Scripted("skipped", F), Scripted("after", S)
    sequence = Sequence("seq", [NodeConditions("skipped", skipped, {"_skipIf": lambda: True}), after])
    assert tick(sequence) == "SUCCESS" and skipped.ticks == 0
    alternative = Scripted("alternative", S)
    fallback = Fallback("fb", [NodeConditions("s", Scripted("x", S), {"_skipIf": lambda: True}), alternative])
    assert tick(fallback) == "SUCCESS" and alternative.ticks == 1  # skipped is not success for a fallback
    everything = Sequence("all", [NodeConditions("s", Scripted("x", S), {"_skipIf": lambda: True})])
    assert tick(everything) == "SKIPPED"


def test_success_if_and_failure_if_decide_without_ticking_the_node():
    child = Scripted("x", R)
    assert tick(NodeConditions("x", child, {"_successIf": lambda: True})) == "SUCCESS"
    assert tick(NodeConditions("x", child, {"_failureIf": lambda: True, "_successIf": lambda: True})) == "FAILURE"
    assert child.ticks == 0
    assert tick(NodeConditions("x", child, {"_failureIf": lambda: False})) == "RUNNING"


def test_while_halts_the_running_node_when_it_becomes_false():
    holds = [True]
    child = Scripted("fly", R)
    node = NodeConditions("fly", child, {"_while": lambda: holds[0]})
    assert tick(node, 2) == "RUNNING"
    holds[0] = False
    assert tick(node) == "SKIPPED"
    assert child.halts == 1


@pytest.mark.parametrize("kind", ["Sequence", "Fallback", "ReactiveSequence"])
def test_halting_a_composite_halts_its_running_child(kind):
    child = Scripted("busy", R)
    children = [Scripted("ok", S if kind != "Fallback" else F), child]
    node = BUILT_IN[kind]("node", children)
    assert tick(node) == "RUNNING"
    node.stop(Status.INVALID)
    assert child.halts == 1 and status_name(node) == "IDLE"
