"""The methods ``@dataclass`` writes for each record class, compiled once and kept in the user's private cache folder.

For every class it decorates, :mod:`dataclasses` writes the source of ``__init__``, ``__repr__``, ``__eq__`` (and
``__setattr__``, ``__delattr__``, ``__hash__`` of a frozen one) and compiles it with ``exec``: ~0.4 ms of CPU per
class, most of it the compiler, and an empty ``aeroexec run`` builds ~85 of them. The source is a pure function of
the class's fields, so its compiled code can be kept: :func:`install` has :mod:`dataclasses` compile through
:func:`exec_kept`, which looks the source up in what a previous ``aeroexec`` command of the same sub-command kept
(``dataclass-code.<command>.v2.<interpreter>.marshal`` in the user's cache folder, :mod:`aeroexec.cache`) and compiles
only what it does not hold; when the command ends, what it compiled is added to the file. The key is the whole
source text, so a class whose fields changed has another source and is compiled again: nothing kept goes stale, and
the file is written for the interpreter that wrote it only (its ``cache_tag`` and version in the name). Each code is
kept marshalled on its own and read when its source is first met: the file holds the classes of every run of the
sub-command (a tree mission's, a plan's...), and a start reads the code of the classes it builds only.

The class built is the one :mod:`dataclasses` builds without it: the same source compiled as ``exec`` compiles it
(file ``<string>``, no inherited ``__future__`` flags), run with the same globals and locals. Without a private
cache folder, or with a file that cannot be read, everything is compiled as before.
"""

from __future__ import annotations

import marshal
import sys

TYPE_CHECKING = False  # typing is not imported at run time
if TYPE_CHECKING:
    from types import CodeType
    from typing import Any

__all__ = ["MOST", "exec_kept", "file_name", "install", "save"]

#: the file's form (in its name): each code marshalled on its own (an aeroexec that reads another form has its own file)
FORMAT = "v2"
#: the most sources one file keeps: past it, a command writes only the ones it used (classes renamed or changed
#: since would otherwise be carried on for ever)
MOST = 4000


class _Kept:
    """The compiled code this process has: what its file held (``codes``: marshalled until first used), what it
    compiled (``compiled``, not yet written), and which sources it used (``used``)."""

    def __init__(self) -> None:
        self.name = ""
        self.codes: dict[str, CodeType | bytes] = {}
        self.compiled = 0
        self.used: set[str] = set()


_kept = _Kept()


def file_name(command: str) -> str:
    """The name of the file the code of ``command``'s dataclasses is kept under, for this interpreter."""
    return f"dataclass-code.{command}.{FORMAT}.{sys.implementation.cache_tag}-{sys.hexversion:x}.marshal"


def exec_kept(source: Any, *args: Any, **kwargs: Any) -> None:
    """:func:`exec`, with a source text compiled once: from the kept code when it holds the text, else compiled
    (and kept). Anything else (a code object) is executed as it is."""
    if type(source) is str:
        code = _kept.codes.get(source)
        if type(code) is bytes:  # kept: read now, once
            try:
                code = marshal.loads(code)
            except (EOFError, ValueError, TypeError):  # damaged: compiled again below (and written anew)
                code = None
            if type(code) is not type(exec_kept.__code__):
                code = None
            else:
                _kept.codes[source] = code
        if code is None:
            code = _kept.codes[source] = compile(source, "<string>", "exec", dont_inherit=True)
            _kept.compiled += 1
        _kept.used.add(source)
        source = code
    exec(source, *args, **kwargs)


def install(command: str) -> None:
    """Have :mod:`dataclasses` compile the classes it builds from now on through :func:`exec_kept`, starting from what
    was kept for ``command``; what is compiled is kept when the process ends (:func:`save`). Once per process."""
    import atexit
    import dataclasses

    from aeroexec.cache import kept

    if getattr(dataclasses, "exec", None) is exec_kept:
        return
    _kept.name = file_name(command)
    data = kept(_kept.name)
    try:
        held = marshal.loads(data) if data else {}
    except (EOFError, ValueError, TypeError):  # a file cut short or not ours: compiled again, and written anew
        held = {}
    if isinstance(held, dict):
        _kept.codes.update((text, code) for text, code in held.items() if type(text) is str and type(code) is bytes)
    dataclasses.exec = exec_kept  # type: ignore[attr-defined]  # looked up in its globals before the builtins
    atexit.register(save)


def save() -> None:
    """Write what this process compiled to its file (atomically: :func:`aeroexec.cache.keep`), beside what the file
    held; past :data:`MOST` sources, only those this process used. Nothing is written when nothing was compiled."""
    if not _kept.compiled or not _kept.name:
        return
    from aeroexec.cache import keep

    codes = _kept.codes
    if len(codes) > MOST:
        codes = {text: code for text, code in codes.items() if text in _kept.used}
    keep(_kept.name, marshal.dumps({text: code if type(code) is bytes else marshal.dumps(code)
                                    for text, code in codes.items()}), most=64)
    _kept.compiled = 0
