"""What each built-in node type is to the XML (BehaviorTree.CPP's ``TreeNodeManifest``): its kind, its ports
(BT.CPP's ``providedPorts()``), how many children it takes and whether it ticks part of its subtree again and again.

One manifest per node name, in :data:`MANIFESTS`; the node's class in the module of its kind takes its declarations
from it (``manifest = MANIFESTS["Repeat"]``) and ``registry`` maps the name to the class. Verification, the Groot2
palette and the ``.btlog`` read the manifests alone: they know every built-in node without importing py_trees or
the node classes.
"""

from __future__ import annotations

from dataclasses import dataclass

from aeroexec.trees.conversions import ANY, BOOL, DOUBLE, INT, STATUS, STRING, UNSIGNED

#: BehaviorTree.CPP's node types (``NodeType``), as its manifests and Groot2's palette name them.
ACTION, CONDITION, CONTROL, DECORATOR, SUBTREE = "Action", "Condition", "Control", "Decorator", "SubTree"


@dataclass(frozen=True, slots=True)
class Port:
    """One port of a node type (BT.CPP's ``PortInfo``): its name, type (``trees.conversions``), direction, default
    text, whether the XML must write it (BT.CPP then fails at the first read of a port left out without a default),
    whether an empty value means something there, and the language its text is written in, which verification checks
    (``script``: BT.CPP's scripts; ``belief``: a belief expression it consults; ``query``: one whose variables it
    writes to the blackboard; ``new_belief``: a belief it adds, whose predicates the mission then knows; ``rules``:
    rules and facts)."""

    name: str
    type: str = STRING
    direction: str = "input"  # input, output, inout
    default: str | None = None
    required: bool = False
    description: str = ""
    empty: bool = False  # an empty value means something (an empty queue, an empty text)
    language: str = ""  # script, belief, query, new_belief, rules; "" : a value of its type

    @property
    def reads(self) -> bool:
        return self.direction != "output"

    @property
    def writes(self) -> bool:
        return self.direction != "input"


def InputPort(name: str, type: str = STRING, default: str | None = None, description: str = "",  # noqa: N802
              required: bool = False, empty: bool = False, language: str = "") -> Port:
    """BT.CPP's ``InputPort<T>(name, default, description)``."""
    return Port(name, type, "input", default, required, description, empty, language)


def OutputPort(name: str, type: str = ANY, description: str = "", required: bool = False) -> Port:  # noqa: N802
    """BT.CPP's ``OutputPort<T>(name, description)``: the ``{key}`` (or plain key) the node writes."""
    return Port(name, type, "output", None, required, description)


def BidirectionalPort(name: str, type: str = ANY, description: str = "",  # noqa: N802
                      required: bool = False, empty: bool = False) -> Port:
    """BT.CPP's ``BidirectionalPort<T>(name, description)``."""
    return Port(name, type, "inout", None, required, description, empty)


@dataclass(frozen=True, slots=True)
class NodeManifest:
    """A node type as the XML sees it: kind, ports, children (``max_children`` None: no limit), loops."""

    kind: str
    ports: tuple[Port, ...] = ()
    min_children: int = 0
    max_children: int | None = 0
    loops: bool = False

    def children_text(self) -> str:
        """How many children the node takes, in words."""
        low, high = self.min_children, self.max_children
        if high == low:
            return {0: "no children", 1: "exactly one child"}.get(low, f"{low} children")
        if high is None:
            return f"at least {low} child{'ren' if low != 1 else ''}"
        return f"{low} or {high} children"


def control(*ports: Port, min_children: int = 1, max_children: int | None = None, loops: bool = False
            ) -> NodeManifest:
    return NodeManifest(CONTROL, ports, min_children, max_children, loops)


def decorator(*ports: Port, loops: bool = False) -> NodeManifest:
    return NodeManifest(DECORATOR, ports, 1, 1, loops)


def action(*ports: Port) -> NodeManifest:
    return NodeManifest(ACTION, ports)


def condition(*ports: Port) -> NodeManifest:
    return NodeManifest(CONDITION, ports)


def _switch(cases: int) -> NodeManifest:
    ports = (InputPort("variable", STRING), *(InputPort(f"case_{i}", STRING) for i in range(1, cases + 1)))
    return control(*ports, min_children=cases + 1, max_children=cases + 1)


def _loop(item: str) -> NodeManifest:
    return decorator(BidirectionalPort("queue", ANY, "the items, ';' between them", required=True, empty=True),
                     InputPort("if_empty", STATUS, "SUCCESS", "the result when the queue is empty"),
                     OutputPort("value", item, "the current item"), loops=True)


def _belief(meaning: str, language: str = "belief") -> Port:
    return InputPort("belief", STRING, required=True, description=meaning, language=language)


def _script(port: str, meaning: str = "the script") -> Port:
    return InputPort(port, STRING, required=True, description=meaning, language="script")


_ENTRY = InputPort("entry", ANY, required=True, description="the blackboard entry to watch")
_CHECK_BELIEF = condition(_belief("a belief expression; SUCCESS when it holds"))

MANIFESTS: dict[str, NodeManifest] = {
    # controls
    "Sequence": control(),
    "SequenceWithMemory": control(),
    "AsyncSequence": control(),
    "ReactiveSequence": control(loops=True),
    "Fallback": control(),
    "AsyncFallback": control(),
    "ReactiveFallback": control(loops=True),
    "Parallel": control(InputPort("success_count", INT, "-1", "children that must succeed (negative: all but -1 - n)"),
                        InputPort("failure_count", INT, "1", "children whose failure fails the node")),
    "ParallelAll": control(InputPort("max_failures", INT, "1", "children whose failure fails the node"), loops=True),
    "IfThenElse": control(min_children=2, max_children=3),
    "WhileDoElse": control(min_children=2, max_children=3, loops=True),
    **{f"Switch{cases}": _switch(cases) for cases in range(2, 7)},
    "TryCatch": control(InputPort("catch_on_halt", BOOL, "false", "a halt during the try-block runs the catch child"),
                        min_children=2),
    # decorators
    "Inverter": decorator(),
    "ForceSuccess": decorator(),
    "ForceFailure": decorator(),
    "Repeat": decorator(InputPort("num_cycles", INT, required=True,
                                  description="successful runs of the child (-1: forever)"), loops=True),
    "RetryUntilSuccessful": decorator(InputPort("num_attempts", INT, required=True,
                                                description="runs of a failing child (-1: forever)"), loops=True),
    "KeepRunningUntilFailure": decorator(loops=True),
    "Timeout": decorator(InputPort("msec", UNSIGNED, required=True,
                                   description="milliseconds before the child is halted")),
    "Delay": decorator(InputPort("delay_msec", UNSIGNED, required=True,
                                 description="milliseconds before the child is ticked")),
    "RunOnce": decorator(InputPort("then_skip", BOOL, "true", "after the first run: SKIPPED, else its result again")),
    "Precondition": decorator(_script("if", "a script"),
                              InputPort("else", STATUS, "FAILURE", "the result when the script does not hold")),
    "LoopInt": _loop(INT),
    "LoopDouble": _loop(DOUBLE),
    "LoopString": _loop(STRING),
    "LoopBool": _loop(BOOL),
    "SkipUnlessUpdated": decorator(_ENTRY),
    "WaitValueUpdate": decorator(_ENTRY),
    # in the XML a SubTree has no children: its child is the tree it names
    "SubTree": NodeManifest(SUBTREE, (InputPort("ID", STRING, required=True, description="the BehaviorTree it runs"),)),
    # actions and conditions
    "AlwaysSuccess": action(),
    "AlwaysFailure": action(),
    "Script": action(_script("code")),
    "ScriptCondition": condition(_script("code")),
    "SetBlackboard": action(InputPort("value", ANY, required=True, description="the value to write", empty=True),
                            BidirectionalPort("output_key", ANY, "the blackboard entry it writes", required=True)),
    "UnsetBlackboard": action(InputPort("key", STRING, required=True, description="the entry to remove")),
    "Sleep": action(InputPort("msec", UNSIGNED, required=True, description="milliseconds to wait")),
    "WasEntryUpdated": action(_ENTRY),
    # the engine's leaves
    "AskBehavior": action(InputPort("behavior", STRING, required=True,
                                    description="a deliberative behavior of the catalog"),
                          OutputPort("result", ANY, "the blackboard key that receives its result", required=True),
                          InputPort("timeout", DOUBLE, description="seconds before the behavior times out")),
    "CheckBelief": _CHECK_BELIEF,
    "Condition": _CHECK_BELIEF,
    "QueryBelief": action(_belief("a belief expression; its variables go to the blackboard", "query")),
    "AddBelief": action(_belief("a ground belief to add", "new_belief"),
                        InputPort("multivalued", BOOL, "false", "a predicate the catalog does not declare may hold "
                                                                "several values at once (default false)")),
    "RemoveBelief": action(_belief("a belief pattern; matching beliefs are removed")),
    "AddRule": action(InputPort("rule", STRING, required=True,
                                description="rules deriving beliefs (head :- body.) and facts", language="rules")),
}

#: The built-ins by kind, as BehaviorTree.CPP's manifests say it (Groot2's palette, the .btlog's tree).
CONTROLS = frozenset(name for name, manifest in MANIFESTS.items() if manifest.kind == CONTROL)
DECORATORS = frozenset(name for name, manifest in MANIFESTS.items() if manifest.kind == DECORATOR)
#: Nodes that tick part of their subtree again and again.
LOOPING = frozenset(name for name, manifest in MANIFESTS.items() if manifest.loops)


def ports_of(kind: str) -> dict[str, Port]:
    """The ports a built-in node declares, by name (empty for any other node)."""
    manifest = MANIFESTS.get(kind)
    return {port.name: port for port in manifest.ports} if manifest is not None else {}
