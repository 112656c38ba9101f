"""Behavior-tree missions as read from a file, before they are verified or built: nodes with their ports and places.

Every loader (BehaviorTree.CPP v4 XML, nested YAML, Aerostack's flat YAML) produces a
:class:`TreeDocument`; verification reads it and reports problems at ``file:line``;
the builder turns it into a ``py_trees`` tree that runs on the engine.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

#: Attributes every node may have besides its ports: BehaviorTree.CPP's pre-conditions (scripts).
PRECONDITIONS = ("_failureIf", "_successIf", "_skipIf", "_while")
#: Scripts run when a node completes: BehaviorTree.CPP's post-conditions.
POSTCONDITIONS = ("_onSuccess", "_onFailure", "_onHalted", "_post")
#: Aerostack's dialect: "false" lets the node of a recurrent behavior succeed once the behavior is active.
WAIT_FOR_COMPLETION = "_wait_for_completion"
#: Attributes that are never ports (nor arguments of a behavior).
COMMON_ATTRIBUTES = ("name", "ID", "_description", "_uid", "_fullpath", "_autoremap", WAIT_FOR_COMPLETION,
                     *PRECONDITIONS, *POSTCONDITIONS)


@dataclass
class TreeNode:
    """One node: its type (``Sequence``, ``GO_TO_POINT``, ``Condition``, ``SubTree``...), its name and ports.

    ``ports`` keeps the attribute values as written (text), blackboard references such as ``{P}``
    included; ``name`` is the ``name`` attribute (or the type when there is none). ``file`` and
    ``line`` say where the node was written (1-based; 0 when unknown). ``named`` is False when the file gave no
    name (a SubTree's ``name`` is then its ID, and BehaviorTree.CPP's path of its instance ends ``ID::uid``).
    """

    type: str
    name: str = ""
    ports: dict[str, str] = field(default_factory=dict)
    children: list[TreeNode] = field(default_factory=list)
    file: str = ""
    line: int = 0
    named: bool = True
    tag: str = ""  # the XML element as written (``Condition``, ``Action``...), for portability checks

    def __post_init__(self) -> None:
        if not self.name:
            self.name = self.type

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}" if self.line else self.file

    def walk(self) -> Iterator[TreeNode]:
        """This node and every node below it, depth first, in document order."""
        stack = [self]
        while stack:  # iterative: linear in the nodes whatever the depth
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))


@dataclass
class TreeDocument:
    """A mission file: its behavior trees by ID and the one to execute."""

    trees: dict[str, TreeNode]  # BehaviorTree ID -> the root node of that tree
    main: str  # the ID of the tree to execute
    file: str = ""
    lines: dict[str, int] = field(default_factory=dict)  # BehaviorTree ID -> the line it is declared on
    warnings: list[tuple[str, int, str]] = field(default_factory=list)  # what the loader read with a warning
    #: what aeroexec reads and BehaviorTree.CPP 4.10 or Groot2 refuses (a raw ``<`` in an attribute, names BT.CPP
    #: 4.10 does not allow): warnings, and errors for ``verify --strict-btcpp``
    not_portable: list[tuple[str, int, str]] = field(default_factory=list)

    @property
    def root(self) -> TreeNode:
        return self.trees[self.main]


class TreeFormatError(ValueError):
    """A mission file that cannot be read as a behavior tree; ``problems`` are ``(file, line, message)``.
    ``leaves``: the behavior and belief nodes that could be read, so their names are checked all the same."""

    def __init__(self, problems: list[tuple[str, int, str]], leaves: list[TreeNode] | None = None) -> None:
        self.problems = list(problems)
        self.leaves = list(leaves or [])
        super().__init__("\n".join(f"{f}:{line}: {m}" if line else f"{f}: {m}" for f, line, m in self.problems))
