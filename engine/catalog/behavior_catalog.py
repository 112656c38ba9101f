"""The behavior catalog (paper section 4.3, Appendix B): load a catalog file, check it, and answer questions about it.

``load_catalog(path)`` reads and validates a catalog; every error and warning
names the file and line. ``default_catalog()`` is the aerial catalog shipped in
``aeroexec.catalogs``.
"""

from __future__ import annotations

import copy
import logging
from collections.abc import Iterable
from dataclasses import replace
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

from aeroexec.beliefs import BeliefMemory, Rule, RuleError
from aeroexec.engine.catalog.descriptors import (
    BehaviorDescriptor,
    CapabilityDescriptor,
    Phenomenon,
    PredicateDeclaration,
    ReactiveRule,
    Transition,
)
from aeroexec.engine.catalog.loader import CatalogContent, CatalogReader
from aeroexec.engine.catalog.safety_rules import SafetyRule
from aeroexec.engine.catalog.vocabulary import check_rules, derived_declarations
from aeroexec.engine.errors import CatalogError, Problem
from aeroexec.engine.yaml_nodes import NodeReader, suggestion

logger = logging.getLogger(__name__)


class BehaviorCatalog:
    """What a robot can do: its behaviors, capabilities, reactive rules, state machines and belief vocabulary."""

    def __init__(self, content: CatalogContent, source: str = "", warnings: Iterable[Problem] = ()) -> None:
        self.source = source
        self.default_timeout = content.default_timeout
        self.behaviors: dict[str, BehaviorDescriptor] = dict(content.behaviors)
        self.lists: dict[str, tuple[str, ...]] = dict(content.lists)
        self.capabilities: dict[str, CapabilityDescriptor] = dict(content.capabilities)
        self.reactive_rules: tuple[ReactiveRule, ...] = tuple(content.reactive)
        #: the operator's safety rules for every mission (a mission's own are added by :meth:`with_safety_rules`)
        self.safety_rules: tuple[SafetyRule, ...] = tuple(content.safety_rules)
        self.transitions: tuple[Transition, ...] = tuple(content.transitions)
        self.predicates: dict[str, PredicateDeclaration] = dict(content.predicates)
        #: the rules that derive beliefs (the catalog's ``rules:``, and those added by :meth:`with_rules`)
        self.rules: tuple[Rule, ...] = tuple(content.rules)
        self.phenomena: dict[str, Phenomenon] = _phenomena(content)
        #: the vehicle's documented limits (``vehicle_limits:``, an extension of Appendix B): name -> value
        self.vehicle_limits: dict[str, float] = dict(content.vehicle_limits)
        self.warnings: list[Problem] = list(warnings)
        #: behaviors the catalog describes that no registered implementation serves (see :meth:`served_by`)
        self.unsupported: frozenset[str] = frozenset()
        self._incompatible = self._incompatibility()

    def __contains__(self, name: object) -> bool:
        return name in self.behaviors

    def __iter__(self):
        return iter(self.behaviors.values())

    def __len__(self) -> int:
        return len(self.behaviors)

    def behavior(self, name: str) -> BehaviorDescriptor | None:
        return self.behaviors.get(name)

    def timed(self, name: str) -> BehaviorDescriptor | None:
        """The behavior ``name`` with its timing and motion (``motion:``, ``duration:``, ``beside:``): its own, or,
        when the catalog says nothing of them (the paper's format), those of the aerial catalog's behavior of the same
        name."""
        descriptor = self.behaviors.get(name)
        if descriptor is None or _timing(descriptor) != _NO_TIMING:
            return descriptor
        reference = default_catalog().behaviors.get(name)
        if reference is None or reference is descriptor or _timing(reference) == _NO_TIMING:
            return descriptor
        return replace(descriptor, **dict(zip(("motion", "duration", "beside"), _timing(reference), strict=True)))

    def motion_of(self, name: str) -> str:
        """How the behavior ``name`` moves the robot (its ``motion:``, see :meth:`timed`; "" when it does not)."""
        descriptor = self.timed(name)
        return descriptor.motion if descriptor is not None else ""

    def with_motion(self, motion: str, preferred: str) -> str:
        """The behavior that moves the robot by ``motion`` (``descriptors.MOTIONS``): ``preferred`` (the engine's
        name for it, ``engine_behaviors``) when the catalog has it, else the first behavior whose ``motion:`` says
        so, else ``preferred``."""
        if preferred in self.behaviors:
            return preferred
        return next((d.name for d in self.behaviors.values() if d.motion == motion), preferred)

    def suggest(self, name: str) -> str:
        """`` (did you mean X?)`` for a misspelt behavior name."""
        return suggestion(name, self.behaviors)

    def incompatible(self, a: str, b: str) -> bool:
        """True when behaviors ``a`` and ``b`` cannot be active at the same time."""
        return a == b or frozenset((a, b)) in self._incompatible

    def incompatible_with(self, name: str) -> frozenset[str]:
        """Every described behavior that cannot be active together with ``name``."""
        return frozenset(other for other in self.behaviors if other != name and self.incompatible(name, other))

    def processes(self) -> set[str]:
        """Every process named by a capability descriptor."""
        return {p for capability in self.capabilities.values() for p in capability.processes}

    def served_by(self, implemented: Iterable[str], reference: BehaviorCatalog | None = None) -> BehaviorCatalog:
        """This catalog as a library serves it: behaviors without an implementation are marked unsupported, and a
        behavior described without ``arguments:`` takes the arguments its implementation is described with in
        ``reference`` (a thin catalog's GO_TO_POINT gets COORDINATES...), one that says nothing of its timing and
        motion takes its implementation's (``motion``, ``duration``, ``beside``); one_of groups of ``reference`` apply
        to the arguments a catalog declares, so a request the implementation cannot serve is refused before flight;
        predicates the catalog does not declare are taken from ``reference``. Returns ``self`` when nothing changes."""
        implemented = set(implemented)
        unsupported = frozenset(name for name in self.behaviors if name not in implemented)
        behaviors = dict(self.behaviors)
        for name, descriptor in self.behaviors.items():
            own = reference.behavior(name) if reference is not None and name in implemented else None
            if own is None or own is descriptor:
                continue
            changes: dict[str, Any] = {}
            if not descriptor.arguments and own.arguments:
                changes.update(arguments=dict(own.arguments), one_of=own.one_of)
            elif not descriptor.one_of and own.one_of:
                groups = tuple(g for g in (tuple(a for a in group if a in descriptor.arguments)
                                           for group in own.one_of) if g)
                if groups:
                    changes.update(one_of=groups)
            if _timing(descriptor) == _NO_TIMING and _timing(own) != _NO_TIMING:  # how its implementation moves
                changes.update(zip(("motion", "duration", "beside"), _timing(own), strict=True))
            if changes:
                behaviors[name] = replace(descriptor, **changes)
        predicates = dict(self.predicates)  # what the implementations write, when the catalog does not say
        for name, declared in (reference.predicates.items() if reference is not None else ()):
            predicates.setdefault(name, declared)
        if unsupported == self.unsupported and behaviors == self.behaviors and predicates == self.predicates:
            return self
        fitted = copy.copy(self)
        fitted.behaviors, fitted.unsupported, fitted.predicates = behaviors, unsupported, predicates
        return fitted

    def with_safety_rules(self, rules: Iterable[SafetyRule]) -> BehaviorCatalog:
        """This catalog with ``rules`` watched too (a mission's, a rules file's); ``self`` when there are none."""
        rules = tuple(rules)
        if not rules:
            return self
        watched = copy.copy(self)
        watched.safety_rules = self.safety_rules + rules
        return watched

    def with_rules(self, rules: Iterable[Rule]) -> BehaviorCatalog:
        """This catalog with ``rules`` added (a rules file, ``--rules``): the predicates they derive join the
        vocabulary that missions are checked against, and an engine built on it derives them. Raises
        :class:`~aeroexec.beliefs.RuleError` (each problem with its file and line) when they cannot be taken."""
        rules = [*self.rules, *rules]
        own = {n: p for n, p in self.predicates.items() if not p.derived}
        problems = check_rules(own, rules)
        if problems:
            raise RuleError(problems)
        fitted = copy.copy(self)
        fitted.rules = tuple(rules)
        fitted.predicates = {**own, **derived_declarations(rules, own)}
        return fitted

    def declare_vocabulary(self, memory: BeliefMemory) -> None:
        """Declare the catalog's predicates (arity, exclusivity, persistence) in a belief memory; its rules are
        added once the computed predicates they may read are registered (``memory.add_rules(catalog.rules)``)."""
        for p in self.predicates.values():
            if not p.computed and not p.derived:
                memory.declare(p.name, p.arity, multivalued=p.multivalued, persistence=p.persistence, values=p.values,
                               aliases=p.aliases)

    def _incompatibility(self) -> set[frozenset[str]]:
        pairs: set[frozenset[str]] = set()
        for behavior in self.behaviors.values():  # incompatible_lists: the behavior against every member
            for list_name in behavior.incompatible_lists:
                for other in self.lists.get(list_name, ()):
                    if other != behavior.name:
                        pairs.add(frozenset((behavior.name, other)))
        clashing = {frozenset((c.name, other)) for c in self.capabilities.values() for other in c.incompatible}
        for a in self.behaviors.values():  # capabilities declared incompatible
            for b in self.behaviors.values():
                if a.name < b.name and any(frozenset((x, y)) in clashing for x in a.capabilities
                                           for y in b.capabilities):
                    pairs.add(frozenset((a.name, b.name)))
        return pairs


_NO_TIMING = ("", None, False)


def _timing(descriptor: BehaviorDescriptor) -> tuple[str, float | str | None, bool]:
    return descriptor.motion, descriptor.duration, descriptor.beside


def _phenomena(content: CatalogContent) -> dict[str, Phenomenon]:
    """Declared phenomena, and for undeclared ones the states the transitions use (first initial state first)."""
    phenomena = dict(content.phenomena)
    for t in content.transitions:
        if t.phenomenon in content.phenomena:
            continue
        known = phenomena.get(t.phenomenon)
        states = list(known.states) if known else []
        states += [s for s in (*t.initial_states, t.final_state) if s not in states]
        initial = known.initial_state if known else t.initial_states[0]
        phenomena[t.phenomenon] = Phenomenon(t.phenomenon, tuple(states), initial, t.line)
    return phenomena


def _check_references(content: CatalogContent, reader: NodeReader, processes: set[str] | None) -> None:
    behaviors, lists, capabilities = content.behaviors, content.lists, content.capabilities
    for kind, name, owner, node in content.references:
        if kind == "list" and name not in lists:
            reader.error(node, f"behavior {owner}: the behavior list {name} does not exist{suggestion(name, lists)}")
        elif kind == "capability" and name not in capabilities:
            reader.warning(node, f"{owner}: the capability {name} is not described, so it is not supported by "
                                 f"the architecture{suggestion(name, capabilities)}")
        elif kind == "reactive" and name not in behaviors:
            reader.error(node, f"reactive_activation: the behavior {name} does not exist{suggestion(name, behaviors)}")
        elif kind in ("list_member", "transition") and name not in behaviors:
            where = f"the behavior list {owner}" if kind == "list_member" else "behavior_transitions"
            reader.warning(node, f"{where} names {name}, which is not described{suggestion(name, behaviors)}")
    for t in content.transitions:
        declared = content.phenomena.get(t.phenomenon)
        for state in (*t.initial_states, t.final_state) if declared else ():
            if state not in declared.states:
                reader.error_at(t.line, f"the state {state} is not a state of {t.phenomenon} "
                                        f"({', '.join(declared.states)}){suggestion(state, declared.states)}")
        for name in t.behaviors if t.argument else ():
            argument = behaviors[name].arguments.get(t.argument) if name in behaviors else None
            if name in behaviors and argument is None:
                reader.error_at(t.line, f"the transition names the argument {t.argument}, which "
                                        f"behavior {name} does not have")
            elif argument is not None and argument.choices and t.argument_value not in argument.choices:
                reader.error_at(t.line, f"the value {t.argument_value} of argument {t.argument} for "
                                        f"behavior {name} is not one of {', '.join(argument.choices)}")
    if processes is not None:
        for capability in capabilities.values():
            missing = [p for p in capability.processes if p not in processes]
            if missing:
                reader.warning_at(capability.line, f"the capability {capability.name} is not supported by the "
                                                   f"architecture: process{'es' if len(missing) > 1 else ''} "
                                                   f"{', '.join(missing)} not declared")


def read_catalog(reader: NodeReader, processes: Iterable[str] | None = None) -> BehaviorCatalog:
    """Build a catalog from a composed document; raises :class:`CatalogError` listing every problem."""
    content = CatalogReader(reader).read()
    if not reader.failed:
        _check_references(content, reader, set(processes) if processes is not None else None)
    reader.problems.sort(key=lambda p: (p.line, p.severity))
    if reader.failed:
        raise CatalogError(reader.problems)
    for warning in reader.problems:
        logger.warning("%s", warning)
    return BehaviorCatalog(content, reader.file, reader.problems)


def load_catalog(path: str | Path, processes: Iterable[str] | None = None) -> BehaviorCatalog:
    """Load and validate a catalog file.

    ``processes`` are the processes the robot's architecture declares; a
    capability needing another one gives a warning. Raises :class:`CatalogError`.
    """
    return read_catalog(NodeReader.from_file(path), processes)


def parse_catalog(text: str, file: str = "<catalog>", processes: Iterable[str] | None = None) -> BehaviorCatalog:
    """Load a catalog from YAML text (``file`` names it in messages)."""
    return read_catalog(NodeReader(text, file), processes)


def default_catalog_path() -> Path:
    return Path(str(resources.files("aeroexec.catalogs").joinpath("aerial.yaml")))


@lru_cache(maxsize=1)
def default_catalog() -> BehaviorCatalog:
    """The aerial behavior catalog shipped with aeroexec (Appendix A's behaviors)."""
    return load_catalog(default_catalog_path())


__all__ = ["BehaviorCatalog", "CatalogError", "default_catalog", "load_catalog", "parse_catalog"]
