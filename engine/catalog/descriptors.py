"""The records of a behavior catalog (paper Appendix B): behaviors, capabilities, rules, transitions, predicates."""

from __future__ import annotations

from dataclasses import dataclass, field

from aeroexec.beliefs import Conjunction
from aeroexec.engine.catalog.arguments import ArgumentDescriptor

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

GOAL_BASED = "goal_based"
RECURRENT = "recurrent"
DELIBERATIVE = "deliberative"
CATEGORIES = (GOAL_BASED, RECURRENT, DELIBERATIVE)

#: How a behavior moves the robot (a catalog's ``motion:``), as the route estimate, the contingencies and the resume
#: read it: ``climb`` (vertically, by its ALTITUDE), ``fly_to`` (to its COORDINATES or by its RELATIVE_COORDINATES,
#: at its SPEED), ``descend`` (lands where it is), ``follow_path`` (along points the estimate does not read),
#: ``hover`` (holds where it is until stopped).
MOTIONS = ("climb", "fly_to", "descend", "follow_path", "hover")

LOWER = "lower"
HIGHER = "higher"


@dataclass(frozen=True, slots=True)
class BehaviorDescriptor:
    """How to request a behavior: category, timeout, arguments, what it is incompatible with, what it needs."""

    name: str
    category: str = GOAL_BASED
    timeout: float | None = None  # seconds; None for recurrent behaviors
    incompatible_lists: tuple[str, ...] = ()
    capabilities: tuple[str, ...] = ()
    arguments: dict[str, ArgumentDescriptor] = field(default_factory=dict)
    one_of: tuple[tuple[str, ...], ...] = ()  # groups of arguments of which exactly one must be given
    preconditions: Conjunction | None = None
    description: str = ""
    service_calls: tuple[str, ...] = ()  # the paper's ROS_service_calls, kept for adapters that need them
    line: int = 0
    motion: str = ""  # how it moves the robot (MOTIONS); "" : it does not move it
    duration: float | str | None = None  # s it takes in place, or the argument saying so; None: not known
    beside: bool = False  # it runs beside the flight (a camera, a watch), taking none of its time

    @property
    def moves(self) -> bool:
        return bool(self.motion)

    @property
    def precondition_text(self) -> str:
        return self.preconditions.text if self.preconditions is not None else ""


@dataclass(frozen=True, slots=True)
class CapabilityDescriptor:
    """A robot feature achieved by running processes (paper Table 4, Figure 7)."""

    name: str
    processes: tuple[str, ...] = ()
    incompatible: tuple[str, ...] = ()
    permanent: bool = False
    alternatives: dict[str, str] = field(default_factory=dict)  # process -> the process to run if it fails
    line: int = 0


@dataclass(frozen=True, slots=True)
class ReactiveRule:
    """Activate ``behavior`` by reaction when ``condition`` holds, at ``priority`` lower or higher than deliberation."""

    behavior: str
    condition: Conjunction | None = None
    priority: str = LOWER
    arguments: dict[str, Any] = field(default_factory=dict)
    line: int = 0

    @property
    def condition_text(self) -> str:
        return self.condition.text if self.condition is not None else ""


@dataclass(frozen=True, slots=True)
class Transition:
    """A valid activation in the state machine of a physical phenomenon (paper Figure 8)."""

    behaviors: tuple[str, ...]
    phenomenon: str
    initial_states: tuple[str, ...]
    final_state: str
    argument: str | None = None
    argument_value: str | None = None
    line: int = 0

    def applies(self, behavior: str, arguments: dict[str, Any]) -> bool:
        """True when this transition is the one a request of ``behavior`` with ``arguments`` follows."""
        if behavior not in self.behaviors:
            return False
        if self.argument is None:
            return True
        return str(arguments.get(self.argument)) == self.argument_value


@dataclass(frozen=True, slots=True)
class Phenomenon:
    """A physical phenomenon (flight, light) with its states and the state a mission starts in."""

    name: str
    states: tuple[str, ...]
    initial_state: str
    line: int = 0


@dataclass(frozen=True, slots=True)
class PredicateDeclaration:
    """A predicate of the belief vocabulary: arity, exclusivity, persistence, computed, derived or stored."""

    name: str
    arity: int
    multivalued: bool = False
    persistence: float | None = None  # seconds; None = permanent
    computed: bool = False  # answered by a function the engine registers, never stored
    derived: bool = False  # derived by the catalog's rules (or a rules file), never stored
    values: tuple[str, ...] = ()  # the atoms its last argument takes (matched without regard to case); () = any
    aliases: dict[str, tuple[str, ...]] = field(default_factory=dict)  # a name for several values in expressions
    description: str = ""
    line: int = 0
