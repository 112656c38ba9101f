"""Reading YAML by its nodes, so that every problem found in a file names its line.

:class:`NodeReader` composes a document with PyYAML and hands out mappings,
sequences and scalars while recording errors and warnings as :class:`Problem`
records with the file and the 1-based line of the node at fault.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

from aeroexec.engine.errors import Problem

from aeroexec.lazy import lazy_module
from aeroexec.limits import MAX_NUMBER_LENGTH, InputError, compose_yaml, read_text

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    import yaml
else:  # imported when a text is read: importing this module (``suggestion``, a cached catalog) reads none
    yaml = lazy_module("yaml")

MAP = "tag:yaml.org,2002:map"
SEQ = "tag:yaml.org,2002:seq"
_NUMBER_TAGS = ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")


def suggestion(name: str, known: Iterable[str]) -> str:
    """`` (did you mean X?)`` for a misspelt name, or an empty string."""
    import difflib  # here: only a misspelt name needs it, not every command that can say one

    close = difflib.get_close_matches(str(name), list(known), n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


def _finite(number: int | float | None) -> bool:
    """True for a number a float can hold (``1e400``, ``.inf`` and a 400-digit integer are not)."""
    try:
        return math.isfinite(float(number))
    except (OverflowError, TypeError):
        return False


def line_of(node: yaml.Node | None) -> int:
    return node.start_mark.line + 1 if node is not None else 0


class NodeReader:
    """Composes one YAML document and reads it node by node, collecting problems."""

    def __init__(self, text: str, file: str) -> None:
        self.file = file
        self.problems: list[Problem] = []
        self._constructor = yaml.constructor.SafeConstructor()
        self.root: yaml.Node | None = None
        try:  # libyaml's parser when PyYAML has it, composed within the readers' limits (aeroexec.limits)
            self.root = compose_yaml(text, file)
        except InputError as exc:
            self.problems.append(Problem("error", exc.message, file, exc.line))

    @classmethod
    def from_file(cls, path: str | Path) -> NodeReader:
        """The reader of a file read within the limits of :mod:`aeroexec.limits` (size, special files, UTF-8)."""
        try:
            text = read_text(path)
        except InputError as exc:
            reader = cls("", str(path))
            reader.problems.append(Problem("error", exc.message, exc.file, exc.line))
            return reader
        return cls(text, str(path))

    # -- problems ---------------------------------------------------------------
    def error(self, node: yaml.Node | None, message: str) -> None:
        self.problems.append(Problem("error", message, self.file, line_of(node)))

    def warning(self, node: yaml.Node | None, message: str) -> None:
        self.problems.append(Problem("warning", message, self.file, line_of(node)))

    def error_at(self, line: int, message: str) -> None:
        self.problems.append(Problem("error", message, self.file, line))

    def warning_at(self, line: int, message: str) -> None:
        self.problems.append(Problem("warning", message, self.file, line))

    @property
    def failed(self) -> bool:
        return any(p.severity == "error" for p in self.problems)

    # -- structure --------------------------------------------------------------
    def mapping(self, node: yaml.Node, what: str, known: Iterable[str] = (),
                aliases: dict[str, str] | None = None) -> dict[str, tuple[yaml.Node, yaml.Node]] | None:
        """The entries of a mapping node by key; unknown keys are errors, ``aliases`` are accepted with a warning."""
        if node.tag != MAP:
            self.error(node, f"{what} must be a mapping of keys to values")
            return None
        known = set(known)
        aliases = aliases or {}
        entries: dict[str, tuple[yaml.Node, yaml.Node]] = {}
        for key_node, value_node in node.value:
            key = str(key_node.value) if isinstance(key_node, yaml.ScalarNode) else "?"
            if key in aliases:
                self.warning(key_node, f"{what}: key {key} is not standard, read as {aliases[key]}")
                key = aliases[key]
            elif known and key not in known:
                self.error(key_node, f"{what}: unknown key {key}{suggestion(key, known)}")
                continue
            if key in entries:
                self.error(key_node, f"{what}: key {key} is given twice (first at line {line_of(entries[key][0])})")
                continue
            entries[key] = (key_node, value_node)
        return entries

    def sequence(self, node: yaml.Node, what: str) -> list[yaml.Node] | None:
        """The items of a sequence node; an empty value (``key:`` alone) is an empty list."""
        if self.is_null(node):
            return []
        if node.tag != SEQ:
            self.error(node, f"{what} must be a list")
            return None
        return list(node.value)

    def names(self, node: yaml.Node, what: str) -> list[tuple[str, yaml.Node]]:
        """A list of names (or a single name) with the node of each."""
        items = [node] if isinstance(node, yaml.ScalarNode) and not self.is_null(node) else self.sequence(node, what)
        found = []
        for item in items or ():
            if not isinstance(item, yaml.ScalarNode) or self.is_null(item):
                self.error(item, f"{what} must be a list of names")
                continue
            found.append((str(item.value), item))
        return found

    # -- scalars ----------------------------------------------------------------
    @staticmethod
    def is_null(node: yaml.Node) -> bool:
        return isinstance(node, yaml.ScalarNode) and node.tag == "tag:yaml.org,2002:null"

    def value(self, node: yaml.Node) -> Any:
        """The Python value of a node as YAML 1.1 reads it."""
        try:
            return self._constructor.construct_object(node, deep=True)
        except yaml.YAMLError as exc:  # an unknown tag such as !foo: an error at its line, the value is None
            self.error(node, f"not a value this reader knows: {getattr(exc, 'problem', None) or exc}")
            return None

    def text(self, node: yaml.Node, what: str) -> str | None:
        """A scalar as written (``ON`` stays ``ON``, not ``True``)."""
        if not isinstance(node, yaml.ScalarNode) or self.is_null(node):
            self.error(node, f"{what} must be a single value")
            return None
        return str(node.value)

    def number(self, node: yaml.Node, what: str, positive: bool = False) -> float | None:
        """A finite number (a whole one stays ``int``), or None with an error recorded."""
        if not (isinstance(node, yaml.ScalarNode) and node.tag in _NUMBER_TAGS) or len(node.value) > MAX_NUMBER_LENGTH:
            self.error(node, f"{what} must be a number, not {self.shown(node)}")
            return None
        number = self.value(node)
        if not _finite(number) or (positive and number <= 0):
            self.error(node, f"{what} must be a {'positive ' if positive else ''}finite number, not {self.shown(node)}")
            return None
        return number

    def integer(self, node: yaml.Node, what: str, minimum: int = 0) -> int | None:
        if not (isinstance(node, yaml.ScalarNode) and node.tag == _NUMBER_TAGS[0]) or not _finite(
                self.value(node)) or self.value(node) < minimum:
            self.error(node, f"{what} must be a whole number of at least {minimum}, not {self.shown(node)}")
            return None
        return int(self.value(node))

    def flag(self, node: yaml.Node, what: str) -> bool | None:
        value = self.value(node) if isinstance(node, yaml.ScalarNode) else None
        if not isinstance(value, bool):
            self.error(node, f"{what} must be yes or no, not {self.shown(node)}")
            return None
        return value

    def shown(self, node: yaml.Node) -> str:
        if isinstance(node, yaml.ScalarNode):
            return repr(node.value) if node.value else "nothing"
        return "a list" if node.tag == SEQ else "a mapping"

    @staticmethod
    def is_number(node: yaml.Node) -> bool:
        return isinstance(node, yaml.ScalarNode) and node.tag in _NUMBER_TAGS
