"""The behavior catalog (paper section 4.3, Appendix B): load a catalog file, check it, and answer questions about it.

``load_catalog(path)`` reads and validates a catalog; every error and warning
names the file and line. ``default_catalog()`` is the aerial catalog shipped in
``aeroexec.catalogs``.
"""

from __future__ import annotations

import contextlib
import copy
import logging
import os
import sys
from collections.abc import Iterable
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

from aeroexec.beliefs import RuleError
from aeroexec.engine.catalog.descriptors import (
    BehaviorDescriptor,
    CapabilityDescriptor,
    Phenomenon,
    PredicateDeclaration,
    ReactiveRule,
    Transition,
)
from aeroexec.engine.errors import CatalogError, Problem
from aeroexec.engine.yaml_nodes import NodeReader, suggestion

from aeroexec.cache import sha256, unpickled, user_cache_folder
from aeroexec.limits import InputError, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # neither the reader nor the memory and the rules engine are imported to load a catalog kept parsed
    from typing import Any

    from aeroexec.beliefs import BeliefMemory, Rule
    from aeroexec.engine.catalog.loader import CatalogContent
    from aeroexec.engine.catalog.safety_rules import SafetyRule

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
        from aeroexec.engine.catalog.vocabulary import check_rules, derived_declarations  # here: only with rules

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
    from aeroexec.engine.catalog.loader import CatalogReader  # here: a catalog kept parsed is not read

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

    A catalog read without errors is kept, parsed, in the user's private cache folder (:mod:`aeroexec.cache`), under
    a key made of the file's name and bytes, the processes and the code that reads it: the next load of the same
    file unpickles it (~2 ms instead of ~25 ms of YAML with line numbers) and logs its warnings again. A changed
    file is read again; one with errors is never kept, so its errors are found and named again every time.
    """
    try:
        text = read_text(path)
    except InputError:
        return read_catalog(NodeReader.from_file(path), processes)  # the reader names the problem
    key = _cache_key(str(path), text, processes)
    cached = _cached_catalog(key)
    if cached is not None:
        for warning in cached.warnings:
            logger.warning("%s", warning)
        return cached
    catalog = read_catalog(NodeReader(text, str(path)), processes)  # raises CatalogError: nothing kept
    _keep_catalog(key, catalog)
    return catalog


def _code_stamp() -> str:
    """The sizes and times of the modules that read a catalog and of those its objects are made of: a changed
    reader never serves a catalog another one parsed."""
    import aeroexec.beliefs
    import aeroexec.engine.catalog

    import aeroexec

    stamp = [aeroexec.__version__]
    for package in (aeroexec.engine.catalog, aeroexec.beliefs):
        for folder in package.__path__:
            for entry in sorted(os.scandir(folder), key=lambda e: e.name):
                if entry.name.endswith(".py"):
                    info = entry.stat()
                    stamp.append(f"{entry.name}:{info.st_size}:{info.st_mtime_ns}")
    yaml_nodes = Path(__file__).resolve().parents[1] / "yaml_nodes.py"
    with contextlib.suppress(OSError):
        info = yaml_nodes.stat()
        stamp.append(f"yaml_nodes:{info.st_size}:{info.st_mtime_ns}")
    return "\n".join(stamp)


def _cache_key(path: str, text: str, processes: Iterable[str] | None) -> str:
    shape = repr((path, None if processes is None else sorted(set(processes)), sys.version_info[:2], _code_stamp()))
    return sha256(shape.encode() + b"\0" + text.encode()).hexdigest()[:32]


def _cached_catalog(key: str) -> BehaviorCatalog | None:
    """The catalog kept under ``key``, None when there is none (or it cannot be read: it is parsed again)."""
    folder = user_cache_folder()
    if folder is None:
        return None
    try:
        data = (folder / f"catalog.{key}.pickle").read_bytes()
    except OSError:
        return None
    try:
        catalog = unpickled(data)
    except Exception:  # noqa: BLE001 (a torn or stale file: the catalog is parsed again and the file rewritten)
        logger.debug("the cached catalog %s could not be read; parsing the file again", key)
        return None
    return catalog if isinstance(catalog, BehaviorCatalog) else None


#: The most parsed catalogs kept: the oldest written are removed beyond it (each changed file or code leaves one).
KEPT_CATALOGS = 32


def _prune(folder: Path) -> None:
    """Remove the oldest kept catalogs beyond :data:`KEPT_CATALOGS` (one removed by another process meanwhile is no
    error; one still in use is parsed again when next loaded)."""
    kept = []
    for entry in os.scandir(folder):
        if entry.name.startswith("catalog.") and entry.name.endswith(".pickle"):
            with contextlib.suppress(OSError):
                kept.append((entry.stat().st_mtime_ns, entry.path))
    for _, path in sorted(kept)[:-KEPT_CATALOGS]:
        with contextlib.suppress(OSError):
            os.unlink(path)


def _keep_catalog(key: str, catalog: BehaviorCatalog) -> None:
    """Write ``catalog`` under ``key`` (atomically: a reader sees the whole file or none); a folder that cannot be
    written is no error."""
    folder = user_cache_folder()
    if folder is None:
        return
    import pickle  # here: only writing a catalog needs pickle.py (reading one: aeroexec.cache.unpickled)
    import tempfile  # here: only writing a catalog needs it (it imports shutil, random...: ~4 ms of a start)

    try:
        data = pickle.dumps(catalog, protocol=pickle.HIGHEST_PROTOCOL)
        with tempfile.NamedTemporaryFile(dir=folder, prefix="catalog.", suffix=".tmp", delete=False) as file:
            file.write(data)
        os.replace(file.name, folder / f"catalog.{key}.pickle")
        _prune(folder)
    except (OSError, pickle.PicklingError, TypeError, AttributeError) as error:
        logger.debug("the parsed catalog was not kept: %s", error)
        with contextlib.suppress(OSError, NameError):
            os.unlink(file.name)


def parse_catalog(text: str, file: str = "<catalog>", processes: Iterable[str] | None = None) -> BehaviorCatalog:
    """Load a catalog from YAML text (``file`` names it in messages)."""
    return read_catalog(NodeReader(text, file), processes)


def default_catalog_path() -> Path:
    import aeroexec.catalogs  # the package's folder (importlib.resources costs ~3 ms of a start to say it)

    return Path(aeroexec.catalogs.__file__).with_name("aerial.yaml")


@lru_cache(maxsize=1)
def default_catalog() -> BehaviorCatalog:
    """The aerial behavior catalog shipped with aeroexec (Appendix A's behaviors)."""
    return load_catalog(default_catalog_path())


__all__ = ["BehaviorCatalog", "CatalogError", "default_catalog", "load_catalog", "parse_catalog"]
