"""The one registration table of the built-in nodes (BehaviorTree.CPP's factory of built-ins): XML name -> class.

A new built-in node is its manifest in ``manifests`` (its kind, ports, children, whether it loops), one class in
the module of its kind (``controls``, ``parallels``, ``branches``, ``decorators``, ``actions``,
``behavior_leaves``, ``belief_leaves``) that takes it (``manifest = MANIFESTS["Name"]``), and one line here. The
builder makes every node through this table; verification reads the manifests alone (no py_trees). A catalog
behavior name is a leaf type of its own (``BehaviorLeaf``).
"""

from __future__ import annotations

from aeroexec.trees.runtime.nodes import (
    actions,
    behavior_leaves,
    belief_leaves,
    branches,
    controls,
    decorators,
    parallels,
)
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
