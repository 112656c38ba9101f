"""Contingencies: what a safety rule's ``contingency:`` may say, one descriptor per word in one table that the rules'
reader, the safety monitor, the end of a flight and the documentation all ask.

A descriptor (:class:`ContingencyKind`) says, for one word as the operator writes it (``hold``, ``return``...):

- how its arguments are read and checked (:meth:`~ContingencyKind.parse`: a :class:`Contingency`, or a sentence
  saying what is wrong, which the reader reports with the file and line);
- its ``severity``: when rules of the same priority are broken, the more conservative contingency takes over;
- how it acts (:meth:`~ContingencyKind.act`) through the :class:`ContingencyActions` the monitor gives it (the
  coordinator at the reactive-higher priority: fly, hover, land, hand over to the mission);
- whether the end of the mission finishes it before the drone lands (``finish_before_landing``), and how the
  end says where the drone then lands (``lands_where``);
- what the views, the report and the docs call it (:meth:`~ContingencyKind.label`, ``syntax``, ``description``).

Other packages add contingencies through the entry-point group ``aeroexec.contingencies``: an entry point names a
:class:`ContingencyKind` subclass (or an instance, or an iterable of either); :func:`contingency_kinds` loads them
the way the behavior library loads its plugins. A built-in word cannot be replaced.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Iterable
from dataclasses import dataclass

from aeroexec.engine.catalog.engine_behaviors import KEEP_HOVERING, LAND
from aeroexec.engine.yaml_nodes import suggestion

from aeroexec.plugins import installed_plugins as plugins

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, ClassVar, Protocol
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

logger = logging.getLogger(__name__)

CONTINGENCIES_GROUP = "aeroexec.contingencies"


@dataclass(frozen=True, slots=True)
class Contingency:
    """A contingency as a rule names it: ``kind`` is its word (hold, return, land, subtree, call, or a plugin's);
    ``target`` its argument as written (the subtree's ID, the function's name); ``home``: a return goes home, not
    to the nearest rally point."""

    kind: str
    target: str = ""
    home: bool = False

    def __str__(self) -> str:
        kinds = contingency_kinds()
        if self.kind in kinds:
            return kinds[self.kind].label(self)
        return " ".join(w for w in (self.kind, self.target) if w)


@dataclass(frozen=True, slots=True)
class ContingencyNames:
    """What a named contingency may name in the mission being checked (None: not known here, anything goes)."""

    subtrees: frozenset[str] | None = None
    functions: frozenset[str] | None = None


class ContingencyActions(Protocol):
    """What a contingency may do when its rule is broken (given by the safety monitor, bound to the rule)."""

    rule: Any  #: the broken SafetyRule
    boundary: tuple | None  #: where the rule last held (None when not known)

    def here(self) -> tuple | None:
        """Where the drone is (ENU m), None when not known."""

    def rally(self, here: tuple, home: bool) -> tuple:
        """The nearest of home and the rally points to ``here`` (home when ``home``)."""

    def take_over(self) -> None:
        """Refuse the mission's requests from now on, naming the rule."""

    def land(self) -> str:
        """Land where the drone is; says so."""

    def fly_to(self, point: tuple, then: str) -> None:
        """Fly to ``point`` at the reactive-higher priority, then activate the behavior ``then`` (KEEP_HOVERING,
        LAND); a flight that cannot arrive hovers (lands when ``then`` is LAND)."""

    def activate(self, behavior: str, arguments: dict | None = None) -> None:
        """Activate a behavior at the reactive-higher priority (the drone lands if it is refused)."""

    def hand_over(self, kind: str, target: str) -> bool:
        """Give the mission its own contingency (a handler the flight registered for ``kind``); False if none."""

    def stop_mission(self) -> None:
        """Stop the behaviors the mission started (what it waited on ends)."""

    def record(self, detail: str) -> None:
        """A ``safety_contingency`` event naming the rule."""


class ContingencyKind:
    """One contingency word: a subclass sets the class attributes and :meth:`act`; :meth:`parse` by default takes
    no argument."""

    name: ClassVar[str] = ""  #: the word as written in a rules file (lower case)
    syntax: ClassVar[str] = ""  #: its form for the docs and error texts, e.g. ``return [home]``
    description: ClassVar[str] = ""  #: what it does, one sentence (the docs table)
    severity: ClassVar[int] = 0  #: between rules of the same priority, the higher takes over (more conservative)
    finish_before_landing: ClassVar[bool] = False  #: the end of the mission finishes it before landing
    lands_where: ClassVar[str] = ""  #: after it is finished, the drone lands where it ... ("holds")

    @property
    def forms(self) -> tuple[str, ...]:
        """Ways to write it, for suggestions (``return``, ``return home``)."""
        return (self.name,)

    def parse(self, arguments: list[str], names: ContingencyNames) -> Contingency | str:
        """The contingency of ``arguments`` (the words after the name), or what is wrong with them, in words."""
        if arguments:
            return f"the contingency {self.name} takes no argument (not {' '.join(arguments)!r})"
        return Contingency(self.name)

    def label(self, contingency: Contingency) -> str:
        """What the events, views and report call it."""
        return " ".join(w for w in (contingency.kind, contingency.target) if w)

    def act(self, contingency: Contingency, actions: ContingencyActions) -> str:
        """Take the contingency; what was done, in words (logged with the violation)."""
        raise NotImplementedError(f"the contingency {self.name} does not say how it acts")


def point_text(point: tuple) -> str:
    """A point as the events show it: ``(1.0, 2.0, 5.0)``."""
    return "(" + ", ".join(f"{v:.1f}" for v in point) + ")"


class Hold(ContingencyKind):
    name, syntax, severity = "hold", "hold", 1
    description = "flies back to where the rule last held (the boundary) and hovers there"
    finish_before_landing, lands_where = True, "holds"

    def act(self, contingency: Contingency, actions: ContingencyActions) -> str:
        actions.take_over()
        here = actions.here()
        if here is None:
            return actions.land()
        target = actions.boundary if actions.boundary is not None else here
        actions.fly_to(target, then=KEEP_HOVERING)
        return f"holding at {point_text(target)}"


class Return(ContingencyKind):
    name, syntax, severity = "return", "return [home]", 2
    description = ("flies to the nearest of home and the rally points (`return home`: home) at the altitude it is "
                   "at, and lands")
    finish_before_landing, lands_where = True, "returned"

    @property
    def forms(self) -> tuple[str, ...]:
        return ("return", "return home")

    def parse(self, arguments: list[str], names: ContingencyNames) -> Contingency | str:
        if not arguments:
            return Contingency(self.name)
        if [a.lower() for a in arguments] == ["home"]:
            return Contingency(self.name, home=True)
        return f"the contingency return takes nothing or home (not {' '.join(arguments)!r})"

    def label(self, contingency: Contingency) -> str:
        return "return home" if contingency.home else "return"

    def act(self, contingency: Contingency, actions: ContingencyActions) -> str:
        actions.take_over()
        here = actions.here()
        if here is None:
            return actions.land()
        target = actions.rally(here, contingency.home)
        point = (target[0], target[1], here[2])
        actions.fly_to(point, then=LAND)
        return f"returning to {point_text(point)} to land"


class Land(ContingencyKind):
    name, syntax, severity = "land", "land", 3
    description = "lands where the drone is"

    def act(self, contingency: Contingency, actions: ContingencyActions) -> str:
        actions.take_over()
        return actions.land()


class _HandOver(ContingencyKind):
    """A contingency of the mission's own: a handler the flight registers serves it; with none, the drone lands."""

    what: ClassVar[str] = ""  #: what the argument names, in words
    stops_mission: ClassVar[bool] = False  #: what the mission waited on ends when it is handed over

    def _known(self, names: ContingencyNames) -> frozenset[str] | None:
        raise NotImplementedError

    def parse(self, arguments: list[str], names: ContingencyNames) -> Contingency | str:
        if len(arguments) != 1:
            given = f", not {' '.join(arguments)!r}" if arguments else ""
            return f"the contingency {self.name} takes the name of one {self.what} ({self.syntax}{given})"
        known = self._known(names)
        if known is not None and arguments[0] not in known:
            return (f"the contingency names the {self.what} {arguments[0]}, which the mission does not have"
                    f"{suggestion(arguments[0], known)}")
        return Contingency(self.name, arguments[0])

    def act(self, contingency: Contingency, actions: ContingencyActions) -> str:
        if actions.hand_over(self.name, contingency.target):
            if self.stops_mission:
                actions.stop_mission()
            return f"handed over to {contingency}"
        actions.record(f"{actions.rule.name}: nothing serves {contingency}; landing")
        actions.take_over()
        return actions.land()


class Subtree(_HandOver):
    name, syntax, what = "subtree", "subtree ID", "subtree"
    description = "halts the mission's tree and runs that tree of the mission instead (XML and YAML trees)"

    def _known(self, names: ContingencyNames) -> frozenset[str] | None:
        return names.subtrees


class Call(_HandOver):
    name, syntax, what, stops_mission = "call", "call FUNCTION", "mission function", True
    description = ("stops what the Python mission waits on and runs that function of the mission instead "
                   "(Python missions)")

    def _known(self, names: ContingencyNames) -> frozenset[str] | None:
        return names.functions


BUILT_IN: tuple[ContingencyKind, ...] = (Hold(), Return(), Land(), Subtree(), Call())


def kinds_of(provider: Any, origin: str) -> list[ContingencyKind]:
    """The contingencies an entry point gives: a :class:`ContingencyKind` subclass or instance, an iterable of
    them, or a callable returning either; a ValueError naming ``origin`` otherwise."""
    if callable(provider) and not isinstance(provider, type) and not isinstance(provider, ContingencyKind):
        provider = provider()
    items = provider if isinstance(provider, Iterable) and not isinstance(provider, str) else [provider]
    found = []
    for item in items:
        if isinstance(item, type) and issubclass(item, ContingencyKind):
            item = item()
        if not isinstance(item, ContingencyKind) or not item.name or item.name != item.name.lower() \
                or len(item.name.split()) != 1:
            raise ValueError(f"{origin} gives {item!r}, not a ContingencyKind with a one-word lower-case name")
        found.append(item)
    return found


@functools.cache
def contingency_kinds() -> dict[str, ContingencyKind]:
    """The table: the built-in contingencies, then every installed package's (``aeroexec.contingencies`` entry
    points), by name; read once a process (``contingency_kinds.cache_clear()`` reads the plugins again)."""
    table = {kind.name: kind for kind in BUILT_IN}
    for origin, provider in plugins(CONTINGENCIES_GROUP):
        try:
            kinds = kinds_of(provider, origin)
        except Exception as exc:  # a plugin's mistake is logged, never takes the engine down
            logger.error("the contingency plugin %s cannot be used: %s", origin, exc)
            continue
        for kind in kinds:
            if kind.name in table:
                logger.error("the contingency plugin %s names %s, which is already a contingency", origin, kind.name)
                continue
            table[kind.name] = kind
    return table


def contingency_forms() -> tuple[str, ...]:
    """Every way of writing a contingency (for suggestions)."""
    return tuple(form for kind in contingency_kinds().values() for form in kind.forms)


def contingency_syntax() -> str:
    """The contingencies as an error text lists them: ``hold, return [home], land, subtree ID, call FUNCTION``."""
    return ", ".join(kind.syntax or kind.name for kind in contingency_kinds().values())


def parse_contingency(text: str, names: ContingencyNames) -> Contingency | str:
    """The contingency ``text`` says, or what is wrong with it, in words (its word is matched in any case)."""
    words = text.split()
    word = words[0].lower() if words else ""
    kind = contingency_kinds().get(word)
    if kind is None:
        return f"unknown contingency {text!r}{suggestion(word, contingency_forms())} (one of {contingency_syntax()})"
    return kind.parse(words[1:], names)


LAND_CONTINGENCY = Contingency(Land.name)  # what a missed deadline escalates to


__all__ = ["BUILT_IN", "CONTINGENCIES_GROUP", "LAND_CONTINGENCY", "Call", "Contingency", "ContingencyActions",
           "ContingencyKind", "ContingencyNames", "Hold", "Land", "Return", "Subtree", "contingency_forms",
           "contingency_kinds", "contingency_syntax", "kinds_of", "parse_contingency", "point_text"]
