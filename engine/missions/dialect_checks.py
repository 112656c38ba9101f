"""What a dialect adds to the static check of Python missions (:mod:`.check`): a table the dialects fill.

A dialect (``aeroexec.dialects``, or another package) declares :class:`DialectChecks` through the entry-point group
``aeroexec.mission_checks``: the mission API modules of its own and the API function each of their functions is
checked as (Aerostack's ``executive_engine_api``: ``executeBehavior`` is ``execute_behavior``), a check of the
whole program (``(nodes, dotted) -> [(node, severity, message[, kind])]``, an error's kind WRONG_FORMAT unless
given: ROS used beyond the drone interface, a spin nothing ends), and the
objects of a program that run behaviors (``(checker) -> ProgramObjects``: Aerostack2's drone interfaces). The
core imports no dialect.
"""

from __future__ import annotations

import ast
import functools
import logging
from collections.abc import Mapping
from dataclasses import dataclass, field

from aeroexec.plugins import installed_plugins, load_reference

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any, Protocol
else:
    Protocol = object  # a structural type to type checkers; a plain class at run time, without typing

logger = logging.getLogger(__name__)

#: The entry-point group dialects declare their checks through.
ENTRY_POINT_GROUP = "aeroexec.mission_checks"


class ProgramObjects(Protocol):
    """A dialect's objects in a program that run behaviors (Aerostack2's drone interfaces), as the checker asks."""

    several: bool  # behaviors run on several drones: the sequences are not checked

    def check(self, call: ast.Call) -> None:
        """Report (to the checker) what is wrong with ``call`` when it is a call of such an object."""

    def sequence_requests(self, call: ast.Call, state: Mapping[str, Any] | None = None,
                          ) -> list[tuple[str, str | None, dict[str, Any], set[str]]]:
        """The requests ``call`` makes (as the checker's ``behavior_requests``), where the phenomena are in
        ``state`` (phenomenon -> :class:`~aeroexec.engine.catalog.specialist.PhenomenonState`, None unknown; None
        when not known at all); empty for any other call."""

    def runs_behaviors(self, call: ast.Call) -> bool:
        """True when ``call`` runs or stops behaviors."""


@dataclass(frozen=True)
class DialectChecks:
    """A dialect's part of the check. ``problems`` and ``objects`` are ``module:function`` references."""

    api_modules: Mapping[str, Mapping[str, str]] = field(default_factory=dict)
    problems: str | None = None
    objects: str | None = None


@functools.cache
def declared() -> tuple[DialectChecks, ...]:
    """The checks of the installed ``aeroexec.mission_checks`` entry points."""
    found = []
    for origin, provided in installed_plugins(ENTRY_POINT_GROUP):
        if isinstance(provided, DialectChecks):
            found.append(provided)
        else:
            logger.error("%s is not a DialectChecks: %r", origin, provided)
    return tuple(found)


def program_problems(nodes: list[ast.AST], dotted: Any) -> list[tuple[Any, ...]]:
    """``(node, severity, message[, kind])`` of every dialect's check of the whole program."""
    return [problem for checks in declared() if checks.problems is not None
            for problem in load_reference(checks.problems)(nodes, dotted)]


def program_objects(checker: Any) -> list[ProgramObjects]:
    """Every dialect's objects of the program ``checker`` checks."""
    return [load_reference(checks.objects)(checker) for checks in declared() if checks.objects is not None]


__all__ = ["ENTRY_POINT_GROUP", "DialectChecks", "ProgramObjects", "declared", "program_objects", "program_problems"]
