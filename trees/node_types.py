"""The node types of behavior-tree missions: BehaviorTree.CPP's built-ins and the engine's leaves, with ports.

Shared by the builder (which makes each type a ``py_trees`` behaviour) and verification (child counts,
known ports, suggestions for misspelt types). A catalog behavior name is a leaf type of its own.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Attributes every node may have besides its ports: BehaviorTree.CPP's pre-conditions take belief expressions here.
PRECONDITIONS = ("_failureIf", "_successIf", "_skipIf", "_while")
#: Scripts run when a node completes: BehaviorTree.CPP's post-conditions.
POSTCONDITIONS = ("_onSuccess", "_onFailure", "_onHalted", "_post")
#: Aerostack's dialect: "false" lets the node of a recurrent behavior succeed once the behavior is active.
WAIT_FOR_COMPLETION = "_wait_for_completion"
#: Attributes that are never arguments of a behavior.
COMMON_ATTRIBUTES = ("name", "ID", "_description", "_uid", "_fullpath", "_autoremap", WAIT_FOR_COMPLETION,
                     *PRECONDITIONS, "_onSuccess", "_onFailure", "_onHalted", "_post")


@dataclass(frozen=True, slots=True)
class NodeType:
    """What a node type allows: how many children (``max_children`` None: no limit) and which ports."""

    name: str
    min_children: int
    max_children: int | None
    ports: tuple[str, ...] = ()
    required: tuple[str, ...] = ()

    def children_text(self) -> str:
        if self.max_children == self.min_children:
            return {0: "no children", 1: "exactly one child"}.get(self.min_children, f"{self.min_children} children")
        if self.max_children is None:
            return f"at least {self.min_children} child{'ren' if self.min_children != 1 else ''}"
        return f"{self.min_children} or {self.max_children} children"


def _control(name: str, ports: tuple[str, ...] = (), minimum: int = 1, maximum: int | None = None) -> NodeType:
    return NodeType(name, minimum, maximum, ports)


def _decorator(name: str, ports: tuple[str, ...] = (), required: tuple[str, ...] = ()) -> NodeType:
    return NodeType(name, 1, 1, ports, required)


def _leaf(name: str, ports: tuple[str, ...] = (), required: tuple[str, ...] = ()) -> NodeType:
    return NodeType(name, 0, 0, ports, required)


CONTROL_TYPES = {t.name: t for t in (
    _control("Sequence"), _control("ReactiveSequence"), _control("SequenceWithMemory"),
    _control("Fallback"), _control("ReactiveFallback"), _control("AsyncSequence"), _control("AsyncFallback"),
    _control("Parallel", ("success_count", "failure_count")),
    _control("IfThenElse", minimum=2, maximum=3), _control("WhileDoElse", minimum=2, maximum=3),
    _control("ParallelAll", ("max_failures",)), _control("TryCatch", ("catch_on_halt",), minimum=2),
    *(_control(f"Switch{n}", ("variable", *(f"case_{i}" for i in range(1, n + 1))), n + 1, n + 1)
      for n in range(2, 7)),
)}
DECORATOR_TYPES = {t.name: t for t in (
    _decorator("Inverter"), _decorator("ForceSuccess"), _decorator("ForceFailure"),
    _decorator("Repeat", ("num_cycles",), ("num_cycles",)),
    _decorator("RetryUntilSuccessful", ("num_attempts",), ("num_attempts",)),
    _decorator("KeepRunningUntilFailure"),
    _decorator("Timeout", ("msec",), ("msec",)),
    _decorator("Delay", ("delay_msec",), ("delay_msec",)),
    _decorator("RunOnce", ("then_skip",)),
    _decorator("Precondition", ("if", "else"), ("if",)),
    *(_decorator(f"Loop{t}", ("queue", "value", "if_empty"), ("queue",)) for t in ("Int", "Double", "String", "Bool")),
    _decorator("SkipUnlessUpdated", ("entry",), ("entry",)), _decorator("WaitValueUpdate", ("entry",), ("entry",)),
)}
#: Leaves that are not catalog behaviors. AskBehavior also takes the behavior's arguments as ports.
LEAF_TYPES = {t.name: t for t in (
    _leaf("AlwaysSuccess"), _leaf("AlwaysFailure"),
    _leaf("Script", ("code",), ("code",)), _leaf("ScriptCondition", ("code",), ("code",)),
    _leaf("SetBlackboard", ("output_key", "value"), ("output_key", "value")),
    _leaf("UnsetBlackboard", ("key",), ("key",)),
    _leaf("Sleep", ("msec",), ("msec",)), _leaf("WasEntryUpdated", ("entry",), ("entry",)),
    _leaf("Condition", ("belief",), ("belief",)), _leaf("CheckBelief", ("belief",), ("belief",)),
    _leaf("QueryBelief", ("belief",), ("belief",)),
    _leaf("AddBelief", ("belief", "multivalued"), ("belief",)),
    _leaf("RemoveBelief", ("belief",), ("belief",)),
    _leaf("AddRule", ("rule",), ("rule",)),
    _leaf("AskBehavior", ("behavior", "result"), ("behavior", "result")),
    _leaf("SubTree", ("ID",), ("ID",)),
)}
BUILT_IN = {**CONTROL_TYPES, **DECORATOR_TYPES, **LEAF_TYPES}

#: Control nodes and decorators that tick part of their subtree again and again.
LOOPING = ("ReactiveSequence", "ReactiveFallback", "WhileDoElse", "Repeat", "RetryUntilSuccessful",
           "KeepRunningUntilFailure", "LoopInt", "LoopDouble", "LoopString", "LoopBool", "ParallelAll")


def bare_key(text: str) -> str | None:
    """The blackboard key of a port written ``{key}``, else None."""
    text = text.strip()
    if len(text) > 2 and text[0] == "{" and text[-1] == "}" and "{" not in text[1:-1] and "}" not in text[1:-1]:
        return text[1:-1].strip()
    return None


def output_key(text: str) -> str:
    """The key an output port writes: ``{key}`` or a plain ``key``."""
    return bare_key(text) or text.strip()
