"""The readers' limits (file size, nesting depth, number length) and the guarded reads that enforce them.

Every reader of a user's file goes through :func:`read_bytes` / :func:`read_text` (a regular file of at
most :data:`MAX_FILE_BYTES`, never a FIFO or a device, UTF-8 with the line of a bad byte) and, for YAML,
:func:`compose_yaml` (nesting, node count and number length bounded, every problem with its line), so a
bad input ends as one :class:`InputError` naming the file and line instead of a traceback or a hang.
docs/reference/limits.md lists these numbers; tests check each one.
"""

from __future__ import annotations

import functools
import os
import stat
from pathlib import Path

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # PyYAML is imported when a YAML text is first read (~15 ms: verify reads no YAML from a cache)
    from typing import Any

    import yaml

#: Largest file a reader accepts (mission, catalog, world, fleet file), in bytes.
MAX_FILE_BYTES = 2 * 1024 * 1024
#: Deepest nesting of YAML collections, XML elements, tree nodes, JSON messages, Python expressions and scripts.
MAX_NESTING = 100
#: Most nodes of a behavior tree with its SubTrees expanded where they are used (the runtime builds them all).
MAX_TREE_NODES = 100_000
#: Most YAML nodes in one document, aliases counted at every place they are used.
MAX_YAML_NODES = 50_000
#: Deepest nesting of a belief term or expression: parentheses, brackets and not() together.
MAX_TERM_DEPTH = 32
#: Most literals in one belief expression (goals, comparisons and negations at its top).
MAX_LITERALS = 100
#: Longest number, in characters, a reader converts (YAML scalars, ports, Python literals).
MAX_NUMBER_LENGTH = 64
#: Most work evaluating rules may spend in one engine step, every ask of the step together (rules files, a catalog's
#: rules, AddRule): a partial answer built or a derived belief stored is one unit (``beliefs/rules/joins.py``);
#: 0.5-2 million units a second on one core (the longest step measured: 54 ms of CPU, at load 14 on 2 cores). Each
#: derived predicate is tried before flight with the facts given (past it: refused with the rule's file:line);
#: past it in flight, the condition asking fails with the rule's file:line.
RULES_WORK_PER_STEP = 30_000
RULES_WORK_WHY = " (the limit of rules in flight, so that the engine loop never stalls)"

_NUMBER_TAGS = ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")
_CHECKED_TAGS = frozenset((*_NUMBER_TAGS, *(f"tag:yaml.org,2002:{kind}" for kind in ("bool", "timestamp", "binary",
                                                                                      "null"))))
_KINDS = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a directory"))


class InputError(ValueError):
    """A file or text that cannot be read: ``file:line: message`` (the line is 0 when the whole file is at fault)."""

    def __init__(self, file: str, line: int, message: str, missing: bool = False) -> None:
        super().__init__(message)
        self.missing = missing  # the file does not exist
        self.file = file
        self.line = line
        self.message = message

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.message}" if self.line else f"{self.file}: {self.message}"


def read_bytes(path: str | Path, limit: int = MAX_FILE_BYTES, what: str = "the file") -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes; FIFOs, devices and directories are refused unread.

    ``what`` names the file in the message when it cannot be opened (``cannot read the world file: ...``).
    """
    name = str(path)
    try:
        kind = os.stat(name).st_mode
    except OSError as exc:
        raise InputError(name, 0, f"cannot read {what}: {exc.strerror or exc}", missing=isinstance(
            exc, FileNotFoundError)) from None
    _refuse_special(name, kind)
    try:  # O_NONBLOCK: a file swapped for a FIFO after the check cannot block the open
        descriptor = os.open(name, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise InputError(name, 0, f"cannot read {what}: {exc.strerror or exc}") from None
    with os.fdopen(descriptor, "rb") as file:
        info = os.fstat(file.fileno())
        _refuse_special(name, info.st_mode)
        if info.st_size > limit:
            raise InputError(name, 0, f"the file is {info.st_size:,} bytes, more than the limit of {limit:,}")
        data = file.read(limit + 1)
    if len(data) > limit:
        raise InputError(name, 0, f"the file is more than the limit of {limit:,} bytes")
    return data


def _refuse_special(name: str, mode: int) -> None:
    for test, what in _KINDS:
        if test(mode):
            raise InputError(name, 0, f"not a regular file: it is {what}, refused before reading")


def decode(data: bytes, file: str) -> str:
    """UTF-8 text of ``data``; a byte that is not UTF-8 is reported by its line and column."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(file, line, f"not UTF-8 text: byte 0x{data[exc.start]:02x} at column {column}") from None


def read_text(path: str | Path, limit: int = MAX_FILE_BYTES, what: str = "the file") -> str:
    """The UTF-8 text of a regular file of at most ``limit`` bytes (see :func:`read_bytes`)."""
    return decode(read_bytes(path, limit, what), str(path))


def line_of_offset(text: str, offset: int) -> int:
    """The 1-based line of a character offset in ``text``."""
    return text.count("\n", 0, max(0, offset)) + 1


@functools.cache
def _bounded_loader() -> tuple[type, bool]:
    """The safe YAML loader class composing within :data:`MAX_NESTING`, :data:`MAX_YAML_NODES` and number length,
    and whether it parses with libyaml; made (PyYAML imported) when a YAML text is first read."""
    import yaml
    from yaml.composer import Composer, ComposerError
    from yaml.constructor import SafeConstructor
    from yaml.resolver import Resolver

    try:  # libyaml scans and parses in C (a 500 KB flow list in 2 s instead of 14 s); composing stays here, bounded
        from yaml._yaml import CParser

        parsing: tuple[type, ...] = (CParser,)
    except ImportError:  # PyYAML without libyaml: the same checks, slower
        from yaml.parser import Parser
        from yaml.reader import Reader
        from yaml.scanner import Scanner

        parsing = (Reader, Scanner, Parser)
    c_parser = len(parsing) == 1

    class _BoundedLoader(*parsing, Composer, SafeConstructor, Resolver):
        """A safe YAML loader composing within :data:`MAX_NESTING`, :data:`MAX_YAML_NODES` and number length."""

        get_single_node = Composer.get_single_node  # PyYAML's composer (the C one would recurse without bounds)
        compose_document = Composer.compose_document
        compose_sequence_node = Composer.compose_sequence_node
        compose_mapping_node = Composer.compose_mapping_node

        def __init__(self, text: str) -> None:
            if c_parser:
                parsing[0].__init__(self, text)
            else:
                parsing[0].__init__(self, text)  # Reader, then Scanner and Parser
                parsing[1].__init__(self)
                parsing[2].__init__(self)
            Composer.__init__(self)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)
            self._depth = 0
            self._nodes = 0
            self._open: set[str] = set()  # anchors being composed: an alias to one would make a cycle
            self._heights: dict[str, tuple[int, int]] = {}  # anchor -> (height, expanded size)
            self._deepest = 0

        def _limit(self, mark: yaml.Mark, message: str) -> None:
            raise ComposerError(None, None, message, mark)

        def compose_node(self, parent, index):  # noqa: ANN001, ANN201 (PyYAML's API)
            event = self.peek_event()
            if isinstance(event, yaml.AliasEvent):
                if event.anchor in self._open:
                    self._limit(event.start_mark, f"the alias *{event.anchor} is inside its own anchor (a cycle)")
                height, size = self._heights.get(event.anchor, (0, 1))
                self._count(size, event.start_mark)
                self._deepest = max(self._deepest, self._depth + height)
                if self._depth + height > MAX_NESTING:
                    self._limit(event.start_mark, f"the alias *{event.anchor} nests the document more than "
                                                  f"{MAX_NESTING} levels deep")
                return Composer.compose_node(self, parent, index)
            if isinstance(event, yaml.ScalarEvent):  # a scalar is no level of nesting: counted, then composed
                self._count(1, event.start_mark)
                if event.anchor is not None:
                    self._heights[event.anchor] = (0, 1)
                return Composer.compose_node(self, parent, index)
            self._depth += 1
            if self._depth > MAX_NESTING:
                self._limit(event.start_mark, f"nested more than {MAX_NESTING} levels deep")
            self._count(1, event.start_mark)
            anchor, before, outer_deepest = event.anchor, self._nodes, self._deepest
            self._deepest = self._depth
            if anchor is not None:
                self._open.add(anchor)
            node = Composer.compose_node(self, parent, index)
            if anchor is not None:
                self._open.discard(anchor)
                self._heights[anchor] = (self._deepest - self._depth + 1, self._nodes - before + 1)
            self._deepest = max(outer_deepest, self._deepest)
            self._depth -= 1
            return node

        def _count(self, nodes: int, mark: yaml.Mark) -> None:
            self._nodes += nodes
            if self._nodes > MAX_YAML_NODES:
                self._limit(mark, f"more than {MAX_YAML_NODES:,} values in one document (aliases counted where used)")

        def compose_scalar_node(self, anchor):  # noqa: ANN001, ANN201
            node = Composer.compose_scalar_node(self, anchor)
            if not node.style:  # libyaml writes a plain scalar's style as "", PyYAML as None
                node.style = None
            if node.tag in _NUMBER_TAGS and len(node.value) > MAX_NUMBER_LENGTH:
                self._limit(node.start_mark, f"a number of {len(node.value)} characters is longer than the limit "
                                             f"of {MAX_NUMBER_LENGTH}")
            if node.tag in _CHECKED_TAGS:  # built once here, so that reading the value later cannot fail
                try:
                    SafeConstructor.construct_object(self, node)
                except Exception as exc:  # PyYAML raises ValueError, KeyError, AttributeError... for these
                    kind = node.tag.rsplit(":", 1)[-1]
                    shown = node.value if len(node.value) <= 40 else node.value[:37] + "..."
                    self._limit(node.start_mark, f"{shown!r} is not a valid {kind} ({type(exc).__name__})")
                finally:
                    self.constructed_objects.pop(node, None)
            return node

    return _BoundedLoader, c_parser


def compose_yaml(text: str, file: str) -> yaml.Node | None:
    """The node tree of one YAML document (None when empty); every problem is an :class:`InputError` with a line."""
    if len(text) > MAX_FILE_BYTES:
        raise InputError(file, 0, f"the text is {len(text):,} characters, more than the limit of {MAX_FILE_BYTES:,}")
    import yaml

    try:
        loader = _bounded_loader()[0](text)
    except yaml.reader.ReaderError as exc:  # a control character, checked as the text is handed over
        raise InputError(file, _reader_line(text, exc), _reader_problem(exc)) from None
    try:
        return loader.get_single_node()
    except yaml.reader.ReaderError as exc:
        raise InputError(file, _reader_line(text, exc), _reader_problem(exc)) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        detail = " ".join(part for part in (exc.context, exc.problem) if part)
        raise InputError(file, mark.line + 1 if mark else 0, f"not valid YAML: {detail}") from None
    except yaml.YAMLError as exc:
        raise InputError(file, 0, f"not valid YAML: {exc}") from None
    except RecursionError:  # not expected within MAX_NESTING; kept so a deep stack never escapes as a traceback
        raise InputError(file, 0, f"not valid YAML: nested too deeply (the limit is {MAX_NESTING})") from None
    finally:
        loader.dispose()


def load_yaml(text: str, file: str) -> Any:
    """The Python value of one YAML document, composed within the limits (see :func:`compose_yaml`)."""
    import yaml
    from yaml.constructor import SafeConstructor

    node = compose_yaml(text, file)
    if node is None:
        return None
    try:
        return SafeConstructor().construct_document(node)
    except yaml.YAMLError as exc:  # e.g. a !!binary that is not base64, a bad timestamp
        mark = getattr(exc, "problem_mark", None)
        raise InputError(file, mark.line + 1 if mark else 0, f"not valid YAML: {getattr(exc, 'problem', exc)}") \
            from None
    except ValueError as exc:
        raise InputError(file, node.start_mark.line + 1, f"not valid YAML: {exc}") from None


def _reader_line(text: str, exc: yaml.reader.ReaderError) -> int:
    """The line of a reader error: libyaml counts the position in UTF-8 bytes, PyYAML in characters."""
    if _bounded_loader()[1]:
        return text.encode("utf-8", "surrogatepass").count(b"\n", 0, max(0, exc.position)) + 1
    return line_of_offset(text, exc.position)


def _reader_problem(exc: yaml.reader.ReaderError) -> str:
    character = exc.character if isinstance(exc.character, int) else ord(exc.character)
    return f"not valid YAML: the control character #x{character:04x} is not allowed (not even in a comment)"


def nesting_beyond(text: str, limit: int, opening: str = "([{", closing: str = ")]}",
                   quotes: str = "\"'") -> int | None:
    """The 0-based offset where brackets outside quoted strings first nest deeper than ``limit``, or None.

    ``quotes`` are the characters that open a string (JSON has only ``"``; belief expressions both).
    """
    depth, quote, escaped = 0, "", False
    for offset, char in enumerate(text):
        if quote:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == quote:
                quote = ""
        elif char in quotes:
            quote = char
        elif char in opening:
            depth += 1
            if depth > limit:
                return offset
        elif char in closing:
            depth = max(0, depth - 1)
    return None
