"""Changes of a running mission (the operator's, from ``aeroexec ctl``, the web console, the live view, a fleet or
Python): what a change is (:class:`MissionChange`), its text form, Aerostack2's mission-update actions mapped onto
it, and the one change a Python mission takes (skip).

| command | argument | what it does |
|---|---|---|
| ``skip`` | | the item running now ends SKIPPED, the mission goes on with the next one (a Python mission: see below) |
| ``jump`` | TARGET | the mission goes on from TARGET (back or forward) |
| ``insert`` | ``before``/``after`` TARGET FRAGMENT | new items before or after TARGET |
| ``modify`` | TARGET PORT=VALUE... | new values for TARGET's ports (a behavior's arguments) |
| ``delete`` | TARGET | TARGET is taken out of the mission |
| ``replace`` | TARGET FRAGMENT | TARGET (an item, or any subtree) is replaced by FRAGMENT |
| ``load`` | FILE | a new mission (any format) replaces the running one in this flight |

TARGET is an item number (a plan's MAVLink item number, else the place in the mission's main sequence, from 1) or a
node's name. FRAGMENT is BehaviorTree.CPP XML (one or more elements) or one behavior written
``BEHAVIOR PORT=VALUE ...``. The argument is read as a shell line (quote what holds spaces).

A Python mission takes skip (the behavior it waits for is stopped: its call returns INTERRUPTED, "skipped by the
operator") and load; its other items cannot be changed while it runs. Every change is checked like a new mission
before it takes effect and refused with the reason when it fails (see :mod:`aeroexec.trees.change_check`); the
supervisor records each one, taken or refused, as a ``mission_change`` event.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, field

from aeroexec.engine.catalog.descriptors import RECURRENT
from aeroexec.engine.events import Outcome
from aeroexec.engine.supervision.commands import CHANGES

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

#: Changes that edit the mission's items (a Python program cannot be edited while it runs).
EDITS = ("insert", "modify", "delete", "replace")
PLACES = ("before", "after")
#: An item number or id as written: ASCII digits only (``str.isdigit`` also takes "²"), at most 9 of them.
ITEM_DIGITS = r"[0-9]{1,9}"  # compiled on first use (re's cache): not at every start
SKIPPED_BY_OPERATOR = "skipped by the operator"
USAGE = {
    "skip": "skip",
    "jump": "jump TARGET",
    "insert": "insert before|after TARGET FRAGMENT",
    "modify": "modify TARGET PORT=VALUE [PORT=VALUE...]",
    "delete": "delete TARGET",
    "replace": "replace TARGET FRAGMENT",
    "load": "load FILE",
}


class ChangeError(ValueError):
    """A change that cannot be read or cannot be made, in words for the operator."""


@dataclass
class ChangeOutcome:
    """What became of a change: taken or not, in words, the problems that refused it, and what the event log keeps
    of it besides (``edits``: how the tree document was changed, to be made again on a resumed run; ``mission``:
    the file a load flies)."""

    ok: bool
    message: str
    problems: list[str] = field(default_factory=list)
    recorded: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class MissionChange:
    """One change of a running mission (see the module's table). Build it with the class methods, or from its text
    with :meth:`parse`; ``argument`` is its text form (what ``aeroexec ctl`` sends)."""

    command: str
    target: str = ""
    fragment: str = ""
    after: bool = False
    ports: tuple[tuple[str, str], ...] = field(default_factory=tuple)
    mission: str = ""

    # -- the Python API --------------------------------------------------------------------------------------
    @classmethod
    def skip(cls) -> MissionChange:
        return cls("skip")

    @classmethod
    def jump(cls, target: str | int) -> MissionChange:
        return cls("jump", str(target))

    @classmethod
    def insert(cls, target: str | int, fragment: str, after: bool = False) -> MissionChange:
        return cls("insert", str(target), fragment, after)

    @classmethod
    def modify(cls, target: str | int, **ports: Any) -> MissionChange:
        return cls("modify", str(target), ports=tuple((k, _text(v)) for k, v in ports.items()))

    @classmethod
    def delete(cls, target: str | int) -> MissionChange:
        return cls("delete", str(target))

    @classmethod
    def replace(cls, target: str | int, fragment: str) -> MissionChange:
        return cls("replace", str(target), fragment)

    @classmethod
    def load(cls, mission: str) -> MissionChange:
        return cls("load", mission=str(mission))

    # -- text ------------------------------------------------------------------------------------------------
    @property
    def words(self) -> list[str]:
        """The argument's words (unquoted)."""
        if self.command == "skip":
            return []
        if self.command == "load":
            return [self.mission]
        if self.command == "insert":
            return ["after" if self.after else "before", self.target, self.fragment]
        if self.command == "modify":
            return [self.target, *(f"{k}={v}" for k, v in self.ports)]
        if self.command in ("replace",):
            return [self.target, self.fragment]
        return [self.target]

    @property
    def argument(self) -> str:
        """The text form of the argument, a shell line."""
        import shlex  # here: a change's words are read only when one comes (~0.3 ms of every run's start)

        return shlex.join(self.words)

    def __str__(self) -> str:
        return f"{self.command} {self.argument}".strip()

    @classmethod
    def parse(cls, command: str, argument: str) -> MissionChange:
        """The change ``command`` with its text ``argument``; :class:`ChangeError` says what is wrong with it."""
        if command not in CHANGES:
            raise ChangeError(f"{command!r} is not a change of the mission ({', '.join(CHANGES)})")
        import shlex  # here: a change's words are read only when one comes (~0.3 ms of every run's start)

        try:
            words = shlex.split(argument)
        except ValueError as error:
            raise ChangeError(f"{command}: the argument cannot be read ({error}); usage: {USAGE[command]}") from None
        if command == "skip":
            if words:
                raise ChangeError("skip takes no argument: it skips the item running now")
            return cls.skip()
        if not words:
            raise ChangeError(f"{command} needs an argument: {USAGE[command]}")
        if command == "load":
            return cls.load(" ".join(words))
        if command == "insert":
            if words[0] not in PLACES or len(words) < 3:
                raise ChangeError(f"usage: {USAGE['insert']} (e.g. insert after 3 'GO_TO_POINT "
                                  f"COORDINATES=\"10, 0, 5\"')")
            fragment = " ".join(words[2:])
            if not fragment.strip():
                raise ChangeError(f"insert: the fragment to insert is missing; usage: {USAGE['insert']}")
            return cls.insert(words[1], fragment, after=words[0] == "after")
        target, rest = words[0], words[1:]
        if command in ("jump", "delete"):
            if rest:
                raise ChangeError(f"usage: {USAGE[command]} (a name with spaces is quoted)")
            return cls(command, target)
        if command == "replace":
            if not " ".join(rest).strip():
                raise ChangeError(f"replace: the fragment to put in its place is missing; usage: {USAGE['replace']}")
            return cls.replace(target, " ".join(rest))
        pairs = []
        for word in rest:
            key, equals, value = word.partition("=")
            if not equals or not key.strip():
                raise ChangeError(f"modify: {word!r} is not PORT=VALUE; usage: {USAGE['modify']}")
            pairs.append((key.strip(), value.strip()))
        if not pairs:
            raise ChangeError(f"usage: {USAGE['modify']}")
        return cls("modify", target, ports=tuple(pairs))


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return ", ".join(_text(v) for v in value)
    return str(value)


# -- Aerostack2's mission updates ------------------------------------------------------------------------------
#: Aerostack2's mission-update actions (``as2_msgs/msg/MissionUpdate.msg``, by name) as aeroexec's commands:
#: aeroexec flies one mission at a time, so a mission loaded flies at once (LOAD, EXECUTE and RESET alike), START
#: goes on from its item, REPEAT starts the mission again from its first item, and STOP lands as ABORT does.
AEROSTACK2_UPDATES = {
    "EXECUTE": "load", "LOAD": "load", "RESET": "load", "START": "jump", "REPEAT": "jump",
    "PAUSE": "pause", "RESUME": "resume", "STOP": "abort", "ABORT": "abort",
    "NEXT_ITEM": "skip", "JUMP_TO": "jump", "INSERT": "insert", "MODIFY": "modify", "REMOVE": "delete",
}


def parse_aerostack2_update(text: str) -> tuple[str, str]:
    """The aeroexec command and argument of an Aerostack2 mission update written ``ACTION [ITEM_ID] [MORE]`` (as
    ``aeroexec ctl update`` takes it): ``MORE`` is the mission file of LOAD/EXECUTE/RESET, the fragment of INSERT,
    the ``PORT=VALUE`` words of MODIFY. Raises :class:`ChangeError`."""
    import shlex  # here: a change's words are read only when one comes (~0.3 ms of every run's start)

    try:
        words = shlex.split(text)
    except ValueError as error:
        raise ChangeError(f"update {text}: {error}") from None
    if not words:
        raise ChangeError(f"update: give Aerostack2's action ({', '.join(AEROSTACK2_UPDATES)}), then the item id "
                          f"and what it needs")
    action, rest = words[0], words[1:]
    item = 0
    if rest and _numeric(rest[0]):  # meant as the item id ("²", "-1" and 5,000 digits are refused as such)
        item = read_item_id(rest.pop(0), f"update {action}")
    more = " ".join(rest)
    return aerostack2_update(action, item, mission=more, fragment=more)


def read_item_id(word: str, said: str = "update") -> int:
    """An Aerostack2 item id as written (ASCII digits, from 0); :class:`ChangeError` names a bad one."""
    if not re.fullmatch(ITEM_DIGITS, word):
        raise ChangeError(f"{said}: {shown(word)} is not an item id (Aerostack2 numbers items 0, 1, 2... written "
                          f"with the digits 0-9); usage: update ACTION [ITEM_ID] [FILE|FRAGMENT]")
    return int(word)


def _numeric(word: str) -> bool:
    digits = word.lstrip("+-").replace(".", "")
    return bool(digits) and all(c.isnumeric() for c in digits)


def shown(word: str, limit: int = 24) -> str:
    """``word`` quoted for a message, cut short when long (a 5,000-digit number is not said whole)."""
    if len(word) <= limit:
        return repr(word)
    return f"{word[:limit]!r}... ({len(word)} characters)"


def aerostack2_update(action: str, item_id: int | str = 0, mission: str = "", fragment: str = "") -> tuple[str, str]:
    """The aeroexec command and argument of one Aerostack2 mission update: ``action`` by name, ``item_id`` as
    Aerostack2 numbers items (from 0), ``mission`` a mission file for the loads, ``fragment`` what INSERT inserts
    and MODIFY's ``PORT=VALUE`` words. Raises :class:`ChangeError` for an action aeroexec has no meaning for."""
    name = str(action).upper()
    command = AEROSTACK2_UPDATES.get(name)
    if command is None:
        raise ChangeError(f"Aerostack2's mission update {action!r} has no meaning here "
                          f"({', '.join(AEROSTACK2_UPDATES)})")
    if isinstance(item_id, str):
        number = read_item_id(item_id.strip(), f"update {name}")
    elif isinstance(item_id, int) and not isinstance(item_id, bool):
        number = item_id
    else:
        raise ChangeError(f"update {name}: {shown(str(item_id))} is not an item id (Aerostack2 numbers items 0, 1, "
                          f"2...)")
    if number < 0:
        raise ChangeError(f"update {name}: {number} is not an item id (Aerostack2 numbers items from 0)")
    import shlex  # here: a change's words are read only when one comes (~0.3 ms of every run's start)

    item = str(number + 1 if name != "REPEAT" else 1)
    if command in ("pause", "resume", "abort", "skip"):
        return command, ""
    if command == "load":
        if not str(mission).strip():
            raise ChangeError(f"update {name}: the mission file to load is missing (update {name} FILE)")
        return command, shlex.quote(mission)
    if command == "jump":
        return command, item
    if command == "insert":
        if not str(fragment).strip():
            raise ChangeError(f"update {name}: the fragment to insert is missing (update INSERT [ITEM_ID] FRAGMENT, "
                              f"e.g. update INSERT 2 'GO_TO_POINT COORDINATES=\"10, 0, 5\"')")
        return command, shlex.join(["before", item, fragment])
    if command == "modify":
        if not str(fragment).strip():
            raise ChangeError(f"update {name}: the new values are missing (update MODIFY ITEM_ID PORT=VALUE..., e.g. "
                              f"update MODIFY 2 SPEED=3)")
        return command, f"{item} {fragment}"
    return command, item


# -- a Python mission -------------------------------------------------------------------------------------------
def ground_transitions(catalog: Any) -> dict[str, tuple[str, str]]:
    """The behaviors that take a phenomenon out of its initial state or back to it (TAKE_OFF and LAND take the
    flight from and to landed): behavior -> (phenomenon, that state). A change never cuts them short."""
    found: dict[str, tuple[str, str]] = {}
    for transition in catalog.transitions:
        phenomenon = catalog.phenomena.get(transition.phenomenon)
        if phenomenon is None:
            continue
        ground = phenomenon.initial_state
        if (ground in transition.initial_states) != (transition.final_state == ground):
            found.update(dict.fromkeys(transition.behaviors, (transition.phenomenon, ground)))
    return found


def not_cut_short(catalog: Any, behavior: str) -> str | None:
    """Why a running ``behavior`` may not be stopped by a change (None when it may)."""
    ground = ground_transitions(catalog).get(behavior)
    if ground is None:
        return None
    return (f"{behavior} is running, and a change does not cut it short (it takes {ground[0]} from or to "
            f"{ground[1]}): change the mission once it ends")


PROGRAM_EDIT = ("a Python mission is a program: its items cannot be changed while it runs (skip skips the behavior it "
                "waits for; load flies a new mission)")


def program_change(engine: Any, change: MissionChange) -> ChangeOutcome:
    """A change of a running Python mission: skip, or why not."""
    if change.command != "skip":
        return ChangeOutcome(False, PROGRAM_EDIT)
    return ChangeOutcome(*skip_program_behavior(engine))


def make_change(engine: Any, changes: Any, aborted: bool, command: str, argument: str, origin: str,
                prepared: Any = None) -> ChangeOutcome:
    """Read a change and have it made by ``changes`` (the flight's; without one, a Python mission's skip only),
    never raising; records it as a ``mission_change`` event (on the engine's thread)."""
    try:
        change = MissionChange.parse(command, argument)
        if aborted:
            outcome = ChangeOutcome(False, "the mission was aborted")
        elif changes is not None:
            outcome = changes.change(change, origin, prepared)
        elif change.command == "load":
            outcome = ChangeOutcome(False, "this engine flies no flight session: a mission cannot be loaded into it")
        elif engine.supervisor.missions:
            outcome = ChangeOutcome(False, "a tree mission's changes are checked and made by its flight session")
        elif engine.bridge.state == "done":  # the mission bridge's DONE: no Python mission runs
            outcome = ChangeOutcome(False, "no mission is running")
        else:
            outcome = program_change(engine, change)
    except ChangeError as error:
        outcome = ChangeOutcome(False, str(error))
    except Exception as exc:  # a change must never take the engine down
        logger.exception("the change %s %s failed", command, argument)
        outcome = ChangeOutcome(False, f"{command} failed: {type(exc).__name__}: {exc}")
    text = outcome.message if outcome.ok else f"refused: {outcome.message}"
    engine.log.record("mission_change", detail=f"{command}{' ' + argument if argument else ''}: {text}",
                      command=command, argument=argument, origin=origin, ok=outcome.ok, problems=outcome.problems,
                      **outcome.recorded)
    return outcome


def skip_program_behavior(engine: Any) -> tuple[bool, str]:
    """``skip`` for a Python mission: the behavior it waits for now (its newest goal-seeking request) is stopped and
    the waiting call returns INTERRUPTED with the reason "skipped by the operator"; the program decides what comes
    next. While paused, the behavior the pause suspended is dropped instead of being requested again."""
    supervisor = engine.supervisor
    suspended = supervisor.suspended_requests()
    if suspended:
        activation = max(suspended, key=lambda a: a.order)
        why = not_cut_short(engine.catalog, activation.name)
        if why:
            return False, why
        supervisor.drop_suspended([activation], Outcome.INTERRUPTED, SKIPPED_BY_OPERATOR)
        return True, f"{activation.name} skipped (paused: it will not be requested again); the mission's call " \
                     f"returns INTERRUPTED"
    waited = [a for a in engine.coordinator.active().values() if a.source == "mission" and a.on_end]
    goals = [a for a in waited if a.category != RECURRENT] or waited
    if not goals:
        return False, "no behavior of the mission is running: nothing to skip"
    activation = max(goals, key=lambda a: a.order)
    why = not_cut_short(engine.catalog, activation.name)
    if why:
        return False, why
    engine.coordinator.stop(activation.name, SKIPPED_BY_OPERATOR)
    return True, f"{activation.name} skipped; the mission's call returns INTERRUPTED ({SKIPPED_BY_OPERATOR})"


__all__ = ["AEROSTACK2_UPDATES", "CHANGES", "EDITS", "ChangeError", "ChangeOutcome", "MissionChange",
           "aerostack2_update", "ground_transitions", "make_change", "not_cut_short", "parse_aerostack2_update",
           "program_change", "read_item_id", "shown", "skip_program_behavior"]
