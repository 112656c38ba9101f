"""The mission formats: one table of what a mission file can be, asked by every part that reads, checks, converts,
describes or completes mission files (``trees.mission_file``, ``flight.missions``, ``trees.mission_world``, the
``run``/``verify``/``convert`` commands and their help, the fuzz suite).

A :class:`MissionFormat` says a format's name, its file suffixes, how a file of a shared suffix is recognised from
its text (``.yaml``, ``.mission``), how it is read (into the tree model, into MAVLink mission items, or,
for a program, checked), and whether ``convert`` can write it. Readers, recognisers and writers are
``module:function`` references, imported when a file of that format is read: the table imports no reader.

Other packages add tree formats through the entry-point group ``aeroexec.mission_formats`` (a :class:`MissionFormat`,
a list of them, or a callable returning either), loaded as the behaviors' entry points are (:mod:`aeroexec.plugins`);
the foreign dialects (``aeroexec.dialects``: TML, Aerostack's nodes, Aerostack2's plans) are added so. They come after
the built-in ones (or ``before`` the format they name), so a suffix they share is theirs only for the files their
recogniser takes. A format read through the XML or YAML reader adds what makes a document its own through the
readers' groups (:data:`XML_DOCUMENTS`, :data:`YAML_FORMS`, :data:`TREE_MAPPINGS`, :data:`TREE_VERIFIERS`). A
tree format's reader is ``(data: str | bytes, file: str, home) -> TreeDocument`` raising
:class:`~aeroexec.trees.model.TreeFormatError` with ``(file, line, message)`` problems; its writer
``(tree, catalog, home) -> str``.
"""

from __future__ import annotations

import functools
import os
from collections import namedtuple

from aeroexec.lazy import lazy_logger
from aeroexec.plugins import installed_plugins, load_reference

TYPE_CHECKING = False  # typing, dataclasses, pathlib and logging are not imported: ``aeroexec --help`` reads this
if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path
    from typing import Any

logger = lazy_logger(__name__)

#: The entry-point group other packages add mission formats through.
ENTRY_POINT_GROUP = "aeroexec.mission_formats"


class MissionFormat(namedtuple("MissionFormat", ("name", "suffixes", "read", "tree", "items", "recognise", "write",
                                                 "writes_as", "summary", "before"),
                               defaults=(True, False, None, None, "", "", ""))):
    """One mission format (an immutable record: a named tuple, which costs ``aeroexec --help`` no import, where a
    dataclass's module costs it ~5 ms). ``read``, ``recognise`` and ``write`` are ``module:function`` references.

    ``tree``: read into the tree model (``read(data, file, home) -> TreeDocument``); else a program, whose
    ``read(source, file, catalog, world)`` checks it (``-> list[Problem]``) and which flies as a Python mission.
    ``items``: MAVLink mission items planned on a map (``read(text, file) -> ItemMission``): placed from a home,
    flown in a world generated around them, their problems numbered by item.
    ``recognise(text) -> bool`` tells a file of this format from another format's of the same suffix; a format
    without one takes the files of its suffixes no other format recognised.
    ``write(tree, catalog, home) -> str``: ``convert --to WRITES_AS`` writes a tree in this format.
    """

    name: str
    suffixes: tuple[str, ...]
    read: str
    tree: bool
    items: bool
    recognise: str | None
    write: str | None
    writes_as: str
    summary: str  # what it is, in a few words: "BehaviorTree.CPP v4 XML"
    before: str  # an added format's place in the table (and the help's lists): before the format of this name

    __slots__ = ()

    def matched(self, name: str) -> int:
        """The length of the longest of this format's suffixes ``name`` ends with (0: none)."""
        lowered = name.lower()
        return max((len(s) for s in self.suffixes if lowered.endswith(s)), default=0)

    def reader(self) -> Callable[..., Any]:
        return load_reference(self.read)

    def writer(self) -> Callable[..., str]:
        if self.write is None:
            raise ValueError(f"{self.name} cannot be written")
        return load_reference(self.write)

    def recognises(self, text: str) -> bool:
        return self.recognise is not None and bool(load_reference(self.recognise)(text))

    def shown(self) -> str:
        """``name (.a, .b)``, as the help texts list it."""
        return f"{self.name} ({', '.join(self.suffixes)})"


#: The entry-point group of readers of XML documents by their document element: ``(root, raw, file, lenient) ->
#: TreeDocument | None`` (None: not theirs), asked before the BehaviorTree.CPP reader (TML's ``<mission>``).
XML_DOCUMENTS = "aeroexec.xml_documents"
#: The entry-point group of the forms of a YAML mission by their top-level key, ``name = key``:
#: ``(reader: NodeReader, root, leaves) -> TreeDocument | None`` (Aerostack's ``nodes:``).
YAML_FORMS = "aeroexec.yaml_forms"
#: The entry-point group of mappings of an XML tree's nodes onto the catalog's: ``(document, home) -> document``
#: (itself when it has none of theirs: Aerostack2's behavior-tree nodes).
TREE_MAPPINGS = "aeroexec.tree_mappings"

#: The entry-point group of verifiers of documents of their own before flight: ``(document, catalog, world) ->
#: list[Problem] | None`` (None: not theirs, the tree checks verify it: a TML mission's own checks).
TREE_VERIFIERS = "aeroexec.tree_verifiers"

_HERE = "aeroexec.trees.mission_file"
_ITEMS = "aeroexec.trees.items"

#: The formats aeroexec reads, in the order a file's suffix and text are matched against them.
BUILT_IN: tuple[MissionFormat, ...] = (
    MissionFormat("Python missions", (".py",), "aeroexec.engine.missions.check:check_mission_source", tree=False,
                  summary="a Python program with a mission() or runMission() function, or an Aerostack2 script"),
    MissionFormat("BehaviorTree.CPP XML", (".xml",), f"{_HERE}:read_xml_tree", write=f"{_HERE}:write_xml_tree",
                  writes_as="xml", summary="BehaviorTree.CPP v4 XML"),
    MissionFormat("YAML trees", (".yaml", ".yml"), f"{_HERE}:read_yaml_tree", summary="a behavior tree in YAML"),
    MissionFormat("QGroundControl plans", (".plan",), f"{_ITEMS}.plan:read_plan", items=True,
                  write=f"{_HERE}:write_plan_file", writes_as="plan", summary="a QGroundControl plan"),
    MissionFormat("QGroundControl legacy missions", (".mission",), f"{_ITEMS}.plan:read_legacy_mission", items=True,
                  recognise=f"{_HERE}:is_legacy_mission", summary="QGroundControl's legacy JSON missions"),
    MissionFormat("QGC WPL 110 waypoint files", (".waypoints", ".txt", ".mission"), f"{_ITEMS}.wpl:read_wpl",
                  items=True, write=f"{_HERE}:write_waypoints_file", writes_as="waypoints",
                  summary="a QGC WPL 110 file"),
)


@functools.cache
def formats() -> tuple[MissionFormat, ...]:
    """The built-in formats, then those of the installed ``aeroexec.mission_formats`` entry points."""
    found = list(BUILT_IN)
    for origin, provided in installed_plugins(ENTRY_POINT_GROUP):
        try:
            provided = provided() if callable(provided) else provided
        except Exception as exc:  # a broken plugin is reported, never takes the command down
            logger.error("the mission format of %s cannot be made: %s", origin, exc)
            continue
        for fmt in [provided] if isinstance(provided, MissionFormat) else list(provided or ()):
            if not isinstance(fmt, MissionFormat) or not fmt.suffixes or not all(s.startswith(".") for s in
                                                                                 fmt.suffixes):
                logger.error("%s is not a MissionFormat with suffixes such as .ext: %r", origin, fmt)
            elif not fmt.tree:  # a program flies as a Python mission: the table cannot say how another would
                logger.error("%s: %s is not a tree format; only tree formats can be added", origin, fmt.name)
            else:
                place = next((i for i, known in enumerate(found) if fmt.before and known.name == fmt.before),
                             len(found))
                found.insert(place, fmt)
    return tuple(found)


@functools.cache
def readers(group: str) -> dict[str, Any]:
    """The loaded entry points of one of the readers' groups (:data:`XML_DOCUMENTS`, :data:`YAML_FORMS`,
    :data:`TREE_MAPPINGS`, :data:`TREE_VERIFIERS`), by name."""
    return dict(installed_plugins(group, named=True))


def suffixes(tree: bool | None = None) -> tuple[str, ...]:
    """Every suffix a mission file may have (only the tree formats' with ``tree=True``), each once."""
    return tuple(dict.fromkeys(s for f in formats() if tree is None or f.tree == tree for s in f.suffixes))


def format_of(name: str | Path, text: str | bytes | None = None) -> MissionFormat | None:
    """The format of the file ``name``: the formats its suffix names (the longest suffix first); of several, the
    first whose recogniser takes ``text``, else the first without a recogniser. None: no format has its suffix."""
    named = [(f.matched(str(name)), f) for f in formats()]
    candidates = [f for length, f in sorted(named, key=lambda pair: -pair[0]) if length]
    if len(candidates) > 1 and text is not None:
        shown = text.decode("utf-8", "replace") if isinstance(text, bytes) else text
        for fmt in candidates:
            if fmt.recognise is not None and fmt.recognises(shown):
                return fmt
    fallback = [f for f in candidates if f.recognise is None] or candidates
    return fallback[0] if fallback else None


def writable() -> dict[str, MissionFormat]:
    """The formats ``convert --to`` writes, by their ``--to`` word."""
    return {f.writes_as: f for f in formats() if f.write and f.writes_as}


def described(tree: bool | None = None) -> str:
    """The formats as the help texts list them: ``Python missions (.py), TML (.tml.xml), ...``."""
    return ", ".join(f.shown() for f in formats() if tree is None or f.tree == tree)


def expected(tree: bool | None = None) -> str:
    """``expected .a, .b or .c``: the suffixes, for an error about a file of none of them."""
    *rest, last = suffixes(tree)
    return f"expected {', '.join(rest)} or {last}" if rest else f"expected {last}"


def complete_mission_files(prefix: str, **_: Any) -> list[str]:
    """Shell completion (argcomplete) of a mission argument: folders, and files of a mission format's suffix."""
    head, slash, start = prefix.rpartition("/")
    shown = head + slash  # "", "folder/" or "/"
    try:
        entries = sorted(os.scandir(shown or "."), key=lambda entry: entry.name)
    except OSError:
        return []
    known = suffixes()
    return [f"{shown}{p.name}/" if p.is_dir() else f"{shown}{p.name}" for p in entries
            if p.name.startswith(start) and (p.is_dir() or p.name.lower().endswith(known))]

__all__ = ["BUILT_IN", "ENTRY_POINT_GROUP", "TREE_MAPPINGS", "TREE_VERIFIERS", "XML_DOCUMENTS", "YAML_FORMS",
           "MissionFormat", "complete_mission_files", "described", "expected", "format_of", "formats", "readers",
           "suffixes", "writable"]
