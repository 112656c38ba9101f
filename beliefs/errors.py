"""Errors of the belief language, in the paper's wording (Table 1, WRONG_FORMAT)."""

from __future__ import annotations


class BeliefError(ValueError):
    """A belief expression the memory cannot accept; ``kind`` is the paper's error type."""

    kind = "WRONG_FORMAT"

    def __init__(self, message: str, expression: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.expression = expression


class BeliefSyntaxError(BeliefError):
    """The text is not a belief expression: says where and what was expected."""

    def __init__(self, expression: str, detail: str = "", column: int | None = None) -> None:
        shown = expression if len(expression) <= 120 else expression[:117] + "..."
        message = f"The format of the belief expression {shown} is not correct"
        if detail:
            message += f" ({detail})"
        super().__init__(message, expression)
        self.detail = detail
        self.column = column


class UnknownPredicateError(BeliefError):
    """The expression uses a predicate outside the declared vocabulary."""

    def __init__(self, predicate: str, expression: str, detail: str = "") -> None:
        message = f"The predicate {predicate} of the belief expression {expression} does not exist"
        if detail:
            message += f" ({detail})"
        super().__init__(message, expression)
        self.predicate = predicate


class EvaluationRefused(BeliefError):
    """Rules whose evaluation would take more memory or work than allowed, refused before it is spent: the
    message names the rule's file and line; a condition asking them fails with it."""

    def __init__(self, detail: str, file: str = "", line: int = 0) -> None:
        where = f"{file or '<rules>'}:{line}" if line else file or "<rules>"
        super().__init__(f"{where}: {detail}")
        self.detail, self.file, self.line = detail, file, line


class RuleProblem:
    """One mistake in a rule, with where it was written (``file:line``, or the column in a one-line text)."""

    __slots__ = ("column", "file", "line", "message")

    def __init__(self, message: str, file: str = "", line: int = 0, column: int | None = None) -> None:
        self.message, self.file, self.line, self.column = message, file, line, column

    def __str__(self) -> str:
        where = self.file or "<rules>"
        if self.line:
            where += f":{self.line}"
            if self.column:
                where += f":{self.column}"
        return f"{where}: {self.message}"

    def __repr__(self) -> str:
        return f"RuleProblem({self})"


class RuleError(BeliefError):
    """Rules the memory cannot take; ``problems`` lists each one with its file and line."""

    def __init__(self, problems: list[RuleProblem]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))
