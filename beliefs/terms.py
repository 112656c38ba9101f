"""Terms of the belief language: variables, compound terms, lists, and their text form.

Ground values are plain Python values so that beliefs are cheap to store and
hash: ``int``/``float`` for numbers, ``str`` for atoms and quoted strings (an
atom ``red`` and a string ``"red"`` are the same value), ``tuple`` for tuples,
:class:`ListTerm` for lists (a tuple subclass, so a list and a tuple with the
same elements unify) and :class:`Struct` for compound terms such as
``box(red)``. Only :class:`Var` marks a non-ground term.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterator

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

_anonymous_ids = itertools.count()
#: Prefix of an anonymous variable's name: ``#`` cannot appear in a variable the user writes (``?[A-Za-z0-9_]*``).
_ANONYMOUS = "?#"


class Var(str):
    """A logic variable written ``?X``; ``?`` alone is anonymous (each one distinct, named ``?#N``).

    A ``str`` subclass so bindings hash at C speed; terms are told apart by
    ``type(x) is Var``, never ``isinstance(x, str)``. Named variables are
    interned, so the ``?X`` of two goals is one object.
    """

    __slots__ = ()
    _interned: dict[str, Var] = {}

    def __new__(cls, name: str) -> Var:
        if name == "?":
            return super().__new__(cls, f"{_ANONYMOUS}{next(_anonymous_ids)}")
        known = cls._interned.get(name)
        if known is None:
            known = super().__new__(cls, name)
            if len(cls._interned) < 100_000:
                cls._interned[name] = known
        return known

    @property
    def name(self) -> str:
        return str.__str__(self)

    @property
    def anonymous(self) -> bool:
        return self.startswith(_ANONYMOUS)

    def __repr__(self) -> str:
        return "?" if self.anonymous else str.__str__(self)

    __str__ = __repr__


class ListTerm(tuple):
    """A list ``[a, b]``: a tuple subclass so it hashes and unifies like a tuple."""

    __slots__ = ()

    def __repr__(self) -> str:
        return "[" + ", ".join(format_term(a) for a in self) + "]"


class Struct:
    """A compound term ``name(arg, ...)``; beliefs are ground Structs."""

    __slots__ = ("_hash", "args", "name")

    def __init__(self, name: str, args: tuple = ()) -> None:
        self.name = name
        self.args = args
        self._hash = hash((name, args))

    @property
    def arity(self) -> int:
        return len(self.args)

    @property
    def signature(self) -> tuple[str, int]:
        return (self.name, len(self.args))

    def __eq__(self, other: object) -> bool:
        return (
            type(other) is Struct
            and other._hash == self._hash
            and other.name == self.name
            and other.args == self.args
        )

    def __hash__(self) -> int:
        return self._hash

    def __repr__(self) -> str:
        return format_term(self)


_SCALARS = (int, float, str)
_BARE_ATOM = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def term(name: str, *args: Any) -> Struct:
    """Build a compound term from Python values: ``term("position", "self", (1, 2, 3))``."""
    return Struct(name, tuple(from_python(a) for a in args))


def from_python(value: Any) -> Any:
    """Turn a Python value into a term: lists become :class:`ListTerm`, recursively."""
    kind = type(value)
    if kind in _SCALARS or kind is Var or kind is Struct:
        return value
    if kind is bool:
        return "true" if value else "false"
    if isinstance(value, list):
        return ListTerm(from_python(v) for v in value)
    if isinstance(value, tuple):
        return type(value)(from_python(v) for v in value) if kind is ListTerm else tuple(
            from_python(v) for v in value
        )
    if isinstance(value, (int, float, str)):  # numpy scalars, str subclasses
        return value.item() if hasattr(value, "item") else value
    raise TypeError(f"{value!r} cannot be a belief value (use numbers, text, tuples or lists)")


def to_python(value: Any) -> Any:
    """Turn a ground term into the Python value a user expects (lists become ``list``)."""
    kind = type(value)
    if kind in _SCALARS or kind is Struct:
        return value
    if kind is ListTerm:
        return [to_python(v) for v in value]
    if kind is tuple:
        for v in value:
            if type(v) not in _SCALARS:
                return tuple(to_python(v) for v in value)
        return value  # a point, a pair of atoms: already the Python value
    return value


def variables(value: Any) -> Iterator[Var]:
    """Yield every variable in a term, left to right (repeats included)."""
    kind = type(value)
    if kind is Var:
        yield value
    elif kind is Struct:
        for a in value.args:
            yield from variables(a)
    elif kind is tuple or kind is ListTerm:
        for a in value:
            yield from variables(a)


def is_ground(value: Any) -> bool:
    """True when the term holds no variable."""
    kind = type(value)
    if kind in _SCALARS:
        return True
    if kind is Var:
        return False
    if kind is Struct:
        return all(is_ground(a) for a in value.args)
    if kind is tuple or kind is ListTerm:
        return all(is_ground(a) for a in value)
    return True


def substitute(value: Any, bindings: dict) -> Any:
    """Replace bound variables in a term by their values."""
    kind = type(value)
    if kind is Var:
        return bindings.get(value, value)
    if kind is Struct:
        return Struct(value.name, tuple(substitute(a, bindings) for a in value.args))
    if kind is tuple:
        return tuple(substitute(a, bindings) for a in value)
    if kind is ListTerm:
        return ListTerm(substitute(a, bindings) for a in value)
    return value


def match(pattern: Any, value: Any, bindings: dict) -> bool:
    """Unify ``pattern`` with the ground ``value``, extending ``bindings`` in place.

    On failure ``bindings`` may hold partial bindings: callers pass a copy.
    """
    kind = type(pattern)
    if kind is Var:
        bound = bindings.get(pattern, pattern)
        if bound is pattern:
            bindings[pattern] = value
            return True
        return bound == value and _same_kind(bound, value)
    if kind is Struct:
        return (
            type(value) is Struct
            and value.name == pattern.name
            and len(value.args) == len(pattern.args)
            and all(match(p, v, bindings) for p, v in zip(pattern.args, value.args, strict=False))
        )
    if kind is tuple or kind is ListTerm:
        return (
            isinstance(value, tuple)
            and type(value) is not Struct
            and len(value) == len(pattern)
            and all(match(p, v, bindings) for p, v in zip(pattern, value, strict=False))
        )
    return pattern == value and _same_kind(pattern, value)


def _same_kind(a: Any, b: Any) -> bool:
    """Equal values of different kinds (``1 == True``) are not the same term."""
    return (type(a) is str) == (type(b) is str)


def format_term(value: Any) -> str:
    """The text form of a term, readable back by the parser."""
    kind = type(value)
    if kind is str:
        return value if _BARE_ATOM.match(value) else _quote(value)
    if kind is int:
        return str(value)
    if kind is float:
        return repr(value)
    if kind is Var:
        return repr(value)
    if kind is Struct:
        if not value.args:
            return value.name
        return value.name + "(" + ", ".join(format_term(a) for a in value.args) + ")"
    if kind is ListTerm:
        return "[" + ", ".join(format_term(a) for a in value) + "]"
    if kind is tuple:
        inner = ", ".join(format_term(a) for a in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    return repr(value)


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


_ESCAPE = re.compile(r"\\(.)", re.DOTALL)
_ESCAPED = {"n": "\n", "t": "\t", "r": "\r"}


def unquote(token: str) -> str:
    """The text of a quoted string token (either quote), with backslash escapes resolved."""
    return _ESCAPE.sub(lambda m: _ESCAPED.get(m.group(1), m.group(1)), token[1:-1])
