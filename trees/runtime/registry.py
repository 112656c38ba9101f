"""The one registration table of the built-in nodes (BehaviorTree.CPP's factory of built-ins): XML name -> class.

A new built-in node is one class in the module of its kind (``controls``, ``parallels``, ``branches``,
``decorators``, ``actions``, ``behavior_leaves``, ``belief_leaves``) declaring its ``ports`` (and its children,
when they differ from its kind's) and one line here. The builder makes every node through this table; verification
reads the classes' declarations (children, ports, which nodes loop). A catalog behavior name is a leaf type of its
own (``BehaviorLeaf``).
"""

from __future__ import annotations

from aeroexec.trees.runtime import (
    actions,
    behavior_leaves,
    belief_leaves,
    branches,
    controls,
    decorators,
    parallels,
)
from aeroexec.trees.runtime.ports import Port
from aeroexec.trees.runtime.ticking import Node

BUILT_IN: dict[str, type[Node]] = {
    # controls
    "Sequence": controls.Sequence,
    "SequenceWithMemory": controls.SequenceWithMemory,
    "AsyncSequence": controls.AsyncSequence,
    "ReactiveSequence": controls.ReactiveSequence,
    "Fallback": controls.Fallback,
    "AsyncFallback": controls.AsyncFallback,
    "ReactiveFallback": controls.ReactiveFallback,
    "Parallel": parallels.Parallel,
    "ParallelAll": parallels.ParallelAll,
    "IfThenElse": branches.IfThenElse,
    "WhileDoElse": branches.WhileDoElse,
    "Switch2": branches.Switch2,
    "Switch3": branches.Switch3,
    "Switch4": branches.Switch4,
    "Switch5": branches.Switch5,
    "Switch6": branches.Switch6,
    "TryCatch": branches.TryCatch,
    # decorators
    "Inverter": decorators.Inverter,
    "ForceSuccess": decorators.ForceSuccess,
    "ForceFailure": decorators.ForceFailure,
    "Repeat": decorators.Repeat,
    "RetryUntilSuccessful": decorators.RetryUntilSuccessful,
    "KeepRunningUntilFailure": decorators.KeepRunningUntilFailure,
    "Timeout": decorators.Timeout,
    "Delay": decorators.Delay,
    "RunOnce": decorators.RunOnce,
    "Precondition": decorators.Precondition,
    "LoopInt": decorators.LoopInt,
    "LoopDouble": decorators.LoopDouble,
    "LoopString": decorators.LoopString,
    "LoopBool": decorators.LoopBool,
    "SkipUnlessUpdated": decorators.SkipUnlessUpdated,
    "WaitValueUpdate": decorators.WaitValueUpdate,
    "SubTree": decorators.SubTree,
    # actions and conditions
    "AlwaysSuccess": actions.AlwaysSuccess,
    "AlwaysFailure": actions.AlwaysFailure,
    "Script": actions.Script,
    "ScriptCondition": actions.ScriptCondition,
    "SetBlackboard": actions.SetBlackboard,
    "UnsetBlackboard": actions.UnsetBlackboard,
    "Sleep": actions.Sleep,
    "WasEntryUpdated": actions.WasEntryUpdated,
    # the engine's leaves
    "AskBehavior": behavior_leaves.AskBehavior,
    "CheckBelief": belief_leaves.CheckBelief,
    "Condition": belief_leaves.Condition,
    "QueryBelief": belief_leaves.QueryBelief,
    "AddBelief": belief_leaves.AddBelief,
    "RemoveBelief": belief_leaves.RemoveBelief,
    "AddRule": belief_leaves.AddRule,
}

#: The built-ins by kind, as BehaviorTree.CPP's manifests say it (Groot2's palette, the .btlog's tree).
CONTROLS = frozenset(name for name, cls in BUILT_IN.items() if issubclass(cls, controls.Control))
DECORATORS = frozenset(name for name, cls in BUILT_IN.items()
                       if issubclass(cls, decorators.Decorator) and cls is not decorators.SubTree)
#: Nodes that tick part of their subtree again and again.
LOOPING = frozenset(name for name, cls in BUILT_IN.items() if cls.loops)


def ports_of(kind: str) -> dict[str, Port]:
    """The ports a built-in node declares, by name (empty for any other node)."""
    cls = BUILT_IN.get(kind)
    return {port.name: port for port in cls.ports} if cls is not None else {}


def children_text(kind: str) -> str:
    """How many children a built-in node takes, in words."""
    cls = BUILT_IN[kind]
    low, high = cls.min_children, cls.max_children
    if high == low:
        return {0: "no children", 1: "exactly one child"}.get(low, f"{low} children")
    if high is None:
        return f"at least {low} child{'ren' if low != 1 else ''}"
    return f"{low} or {high} children"
