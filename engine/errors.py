"""Specification errors of the engine in the paper's wording (Table 1), and catalog problems with file and line."""

from __future__ import annotations

from dataclasses import dataclass

WRONG_FORMAT = "WRONG_FORMAT"
WRONG_VALUE = "WRONG_VALUE"
WRONG_SEQUENCE = "WRONG_SEQUENCE"
#: A catalog behavior the robot has no implementation of (no class registered in the behavior library).
UNSUPPORTED = "UNSUPPORTED"


def unsupported_message(behavior: str) -> str:
    return f"The behavior {behavior} is not supported by this robot (no implementation is registered)"


class SpecificationError(ValueError):
    """A mistake in what the operator wrote, found before execution.

    ``kind`` is WRONG_FORMAT, WRONG_VALUE or WRONG_SEQUENCE; ``message`` is the
    paper's sentence; ``step`` is the index of the offending request when a
    sequence was checked; ``others`` holds further errors found in the same request.
    """

    def __init__(self, kind: str, message: str, *, behavior: str = "", step: int | None = None,
                 others: tuple[SpecificationError, ...] = ()) -> None:
        super().__init__(message)
        self.kind = kind
        self.message = message
        self.behavior = behavior
        self.step = step
        self.others = others

    def __str__(self) -> str:
        return self.message

    def __repr__(self) -> str:
        return f"SpecificationError({self.kind}: {self.message})"


@dataclass(frozen=True, slots=True)
class Problem:
    """One finding while loading a catalog: an error stops the load, a warning does not."""

    severity: str  # "error" or "warning"
    message: str
    file: str
    line: int  # 1-based; 0 when unknown

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}" if self.line else self.file
        return f"{where}: {self.severity}: {self.message}"


@dataclass(frozen=True, slots=True)
class MissionProblem(Problem):
    """A problem in a mission program: the paper's error type and the column as well (1-based; 0 unknown)."""

    kind: str = ""
    column: int = 0

    def __str__(self) -> str:
        where = self.file + (f":{self.line}" if self.line else "") + (f":{self.column}" if self.line and
                                                                         self.column else "")
        return f"{where}: {self.severity}: {self.kind + ': ' if self.kind else ''}{self.message}"


class CatalogError(ValueError):
    """A catalog that cannot be loaded; ``problems`` lists every error and warning found."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = list(problems)
        self.errors = [p for p in self.problems if p.severity == "error"]
        super().__init__("\n".join(str(p) for p in self.errors) or "the catalog cannot be loaded")


class RequestRejected(SpecificationError):
    """A mission's request that ``verify`` would have refused had its values been literal, found at run time
    (a computed behavior name that does not exist, a value out of range, a behavior with no implementation).
    It is raised in the mission at the call (``where`` is the mission's ``file:line``); FAILED_PRECONDITIONS
    and the other execution outcomes stay return values (Table 8)."""

    def __init__(self, kind: str, message: str, *, behavior: str = "", where: str = "") -> None:
        super().__init__(kind, message, behavior=behavior)
        self.where = where

    def __str__(self) -> str:
        return f"{self.behavior} rejected ({self.kind}): {self.message}" + (f" [{self.where}]" if self.where else "")


class MissionAborted(RuntimeError):
    """The engine stopped while the mission waited on it."""
