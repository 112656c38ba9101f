"""The behavior specialist (paper section 4.3): checks requests, compatibility and sequences against the catalog.

Every error is a :class:`SpecificationError` in the paper's wording (Table 1):
WRONG_FORMAT and WRONG_VALUE for a request, WRONG_SEQUENCE for a sequence the
state machines of the physical phenomena do not allow.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from aeroexec.beliefs import BeliefError, Conjunction
from aeroexec.beliefs.expression import Goal, Negation
from aeroexec.beliefs.parser import check_expression
from aeroexec.beliefs.terms import Struct, format_term
from aeroexec.drones.geodesy import Geodetic
from aeroexec.engine.catalog.arguments import format_value
from aeroexec.engine.catalog.behavior_catalog import BehaviorCatalog, default_catalog
from aeroexec.engine.catalog.descriptors import BehaviorDescriptor
from aeroexec.engine.catalog.places import localize
from aeroexec.engine.catalog.world_check import WorldMap, world_problems
from aeroexec.engine.errors import WRONG_FORMAT, WRONG_SEQUENCE, WRONG_VALUE, SpecificationError
from aeroexec.engine.yaml_nodes import suggestion

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    #: a step of a sequence or plan: a behavior's name, with its arguments, or a request's mapping
    Step = str | tuple[str, Mapping[str, Any]] | Mapping[str, Any]


@dataclass(frozen=True, slots=True)
class Request:
    """A request to activate a behavior with arguments, as a mission plan writes it."""

    behavior: str
    arguments: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class PhenomenonState:
    """Where a physical phenomenon is, and the behavior that brought it there (None at the start)."""

    state: str
    since: str | None = None


def _goals(expression: Conjunction) -> Iterable[Struct]:
    for literal in expression.literals:
        if type(literal) is Goal:
            yield literal.term
        elif type(literal) is Negation:
            yield from _goals(literal.body)


def as_request(step: Step | Request) -> Request:
    """A :class:`Request` from a name, a ``(name, arguments)`` pair or a ``{"behavior": ..., "arguments": ...}``."""
    if isinstance(step, Request):
        return step
    if isinstance(step, str):
        return Request(step)
    if isinstance(step, Mapping):
        return Request(str(step.get("behavior", "")), dict(step.get("arguments") or {}))
    name, arguments = step
    return Request(name, dict(arguments or {}))


def canonical_arguments(descriptor: BehaviorDescriptor, arguments: Mapping[str, Any] | None) -> dict[str, Any]:
    """The arguments under the catalog's names: an alias (``POINT`` for ``COORDINATES``) is renamed."""
    aliases = {alias: a.name for a in descriptor.arguments.values() for alias in a.aliases}
    return {aliases.get(key, key) if key not in descriptor.arguments else key: value
            for key, value in (arguments or {}).items()}


class BehaviorSpecialist:
    """Knows how each behavior must be requested and which behaviors and sequences are possible."""

    def __init__(self, catalog: BehaviorCatalog | None = None, world: WorldMap | None = None,
                 home: Callable[[], Geodetic | None] | None = None) -> None:
        self.catalog = catalog if catalog is not None else default_catalog()
        #: When given (verification with a world), literal destinations and paths are checked against it.
        self.world = world
        #: Where ``geo:`` places are placed from: the flying drone's home (in flight), else the world's home.
        self.home = home if home is not None else (lambda: getattr(world, "home", None))

    def placed(self, descriptor: BehaviorDescriptor, arguments: Mapping[str, Any] | None) -> dict[str, Any]:
        """The arguments under the catalog's names, their ``geo:`` places in ENU meters when a home is known."""
        arguments = canonical_arguments(descriptor, arguments)
        if any(isinstance(v, str) for v in arguments.values()) or any(
                isinstance(v, list | tuple) and any(isinstance(p, str) for p in v) for v in arguments.values()):
            return localize(descriptor, arguments, self.home())
        return arguments

    # -- requests ---------------------------------------------------------------
    def check_request(self, name: str, arguments: Mapping[str, Any] | None = None) -> BehaviorDescriptor:
        """The behavior's descriptor when the request is correct; else raise its first error (rest in ``others``)."""
        errors = self.request_errors(name, arguments)
        if errors:
            first = errors[0]
            raise SpecificationError(first.kind, first.message, behavior=first.behavior, others=tuple(errors[1:]))
        return self.catalog.behaviors[name]

    def request_errors(self, name: str, arguments: Mapping[str, Any] | None = None) -> list[SpecificationError]:
        """Every WRONG_FORMAT and WRONG_VALUE error of a request, in the order the operator reads them."""
        descriptor = self.catalog.behavior(name) if isinstance(name, str) else None
        if descriptor is None:
            return [SpecificationError(WRONG_FORMAT, f"The behavior {name} does not exist"
                                                     f"{self.catalog.suggest(str(name))}", behavior=str(name))]
        arguments = self.placed(descriptor, arguments)
        errors = []

        def error(kind: str, message: str) -> None:
            errors.append(SpecificationError(kind, message, behavior=name))

        if name in self.catalog.unsupported:
            error(WRONG_FORMAT, f"The behavior {name} is not supported by this robot (no implementation is "
                                f"registered)")
        known = descriptor.arguments
        for key, value in arguments.items():
            argument = known.get(key)
            if argument is None:
                hint = suggestion(key, known) if known else " (it takes no arguments)"
                error(WRONG_FORMAT, f"The argument {key} of behavior {name} does not exist{hint}")
            elif not argument.accepts(value):
                error(WRONG_VALUE, f"The value {format_value(value)} of argument {key} for behavior {name} "
                                   f"is not correct ({argument.expected()} is expected)")
        for argument in known.values():
            if argument.required and argument.default is None and argument.name not in arguments:
                error(WRONG_FORMAT, f"The argument {argument.name} of behavior {name} is missing "
                                    f"({argument.expected()} is expected)")
        for group in descriptor.one_of:
            given = [a for a in group if a in arguments]
            if not given:
                error(WRONG_FORMAT, f"The behavior {name} needs one of the arguments {', '.join(group)}")
            elif len(given) > 1:
                error(WRONG_FORMAT, f"The arguments {' and '.join(given)} of behavior {name} "
                                    f"cannot be given together")
        if self.world is not None and not errors:
            for key, why in world_problems(descriptor, arguments, self.world):
                error(WRONG_VALUE, f"The value {format_value(arguments[key])} of argument {key} for behavior "
                                   f"{name} is not correct: {why}")
        return errors

    def resolve_arguments(self, name: str, arguments: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """A checked request's arguments with the catalog's defaults filled in."""
        descriptor = self.check_request(name, arguments)
        resolved = {a.name: a.default for a in descriptor.arguments.values() if a.default is not None}
        resolved.update(self.placed(descriptor, arguments))
        return resolved

    def check_expression(self, text: str | Conjunction) -> Conjunction:
        """Parse a belief expression against the catalog's vocabulary; raise WRONG_FORMAT in the paper's words."""
        vocabulary = {p.name: p.arity for p in self.catalog.predicates.values()}
        try:
            return check_expression(text, vocabulary)  # as a memory checks it, without one
        except BeliefError as exc:
            raise SpecificationError(WRONG_FORMAT, exc.message) from None

    def unwritten_values(self, expression: Conjunction) -> list[str]:
        """Why goals of ``expression`` can never hold: they compare a predicate whose values the catalog declares
        to a value no updater writes (``battery_level(self, critical)``); case does not matter."""
        messages = []
        for goal in _goals(expression):
            declared = self.catalog.predicates.get(goal.name)
            if declared is None or not declared.values or not goal.args:
                continue
            value = goal.args[-1]
            spellings = {v.lower() for v in (*declared.values, *declared.aliases)}
            if type(value) is str and value.lower() not in spellings:
                messages.append(f"The belief {format_term(goal)} can never hold: {goal.name} is written with "
                                f"{', '.join(declared.values)}, never {value}")
        return messages

    # -- compatibility ------------------------------------------------------------
    def compatible(self, a: str, b: str) -> bool:
        """True when behaviors ``a`` and ``b`` may be active at the same time."""
        return not self.catalog.incompatible(a, b)

    def conflicts(self, name: str, active: Iterable[str]) -> set[str]:
        """The active behaviors that activating ``name`` would conflict with."""
        return {other for other in active if other != name and self.catalog.incompatible(name, other)}

    # -- sequences ----------------------------------------------------------------
    def initial_states(self, overrides: Mapping[str, str] | None = None) -> dict[str, PhenomenonState]:
        """Each phenomenon's state at the start of a mission (landed, lights off), unless overridden."""
        states = {name: PhenomenonState(p.initial_state) for name, p in self.catalog.phenomena.items()}
        for name, state in (overrides or {}).items():
            states[name] = PhenomenonState(state)
        return states

    def advance(self, states: Mapping[str, PhenomenonState], step: Step | Request,
                index: int | None = None) -> tuple[dict[str, PhenomenonState], list[SpecificationError]]:
        """Apply one request to the phenomena's states: the new states and any WRONG_SEQUENCE errors.

        A request the state machine does not allow is reported and then taken as
        done, so one mistake is reported once rather than at every later step.
        """
        request = as_request(step)
        new_states = dict(states)
        errors = []
        arguments = dict(request.arguments)
        for phenomenon, current in states.items():
            candidates = [t for t in self.catalog.transitions
                          if t.phenomenon == phenomenon and t.applies(request.behavior, arguments)]
            if not candidates:
                continue
            valid = next((t for t in candidates if current.state in t.initial_states), None)
            if valid is None:
                errors.append(self._sequence_error(request.behavior, phenomenon, current, candidates, index))
                valid = candidates[0]
            new_states[phenomenon] = PhenomenonState(valid.final_state, request.behavior)
        return new_states, errors

    def check_sequence(self, steps: Iterable[Step | Request],
                       initial: Mapping[str, str] | None = None) -> list[SpecificationError]:
        """Every WRONG_SEQUENCE error of a sequence of requests, starting from ``initial`` (default: landed, off)."""
        states = self.initial_states(initial)
        errors: list[SpecificationError] = []
        for index, step in enumerate(steps):
            states, found = self.advance(states, step, index)
            errors.extend(found)
        return errors

    def check_plan(self, steps: Iterable[Step | Request],
                   initial: Mapping[str, str] | None = None) -> list[SpecificationError]:
        """Every specification error of a sequence: each request's format and values, then the sequence."""
        requests = [as_request(s) for s in steps]
        errors: list[SpecificationError] = []
        for index, request in enumerate(requests):
            for error in self.request_errors(request.behavior, request.arguments):
                error.step = index
                errors.append(error)
        errors.extend(self.check_sequence(requests, initial))
        errors.sort(key=lambda e: e.step if e.step is not None else -1)
        return errors

    def _sequence_error(self, behavior: str, phenomenon: str, current: PhenomenonState,
                        candidates: list, index: int | None) -> SpecificationError:
        allowed = []
        for t in candidates:
            allowed += [s for s in t.initial_states if s not in allowed]
        after = f"after the execution of {current.since}" if current.since else "at the start of the mission"
        message = (f"The execution of behavior {behavior} cannot be done {after} "
                   f"({phenomenon} is {current.state}; {behavior} needs {' or '.join(allowed)})")
        return SpecificationError(WRONG_SEQUENCE, message, behavior=behavior, step=index)
