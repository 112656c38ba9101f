"""Reading a behavior-tree mission file of any format of the table (:mod:`aeroexec.trees.formats`): its suffix, and
for a suffix several formats share its text, choose the format, whose reader makes it a
:class:`~aeroexec.trees.model.TreeDocument`.

The built-in formats' readers are here, each importing its loader when a file of its format is read: ``.xml``
(BehaviorTree.CPP v4, :mod:`aeroexec.trees.loaders.xml_loader`, or a document a dialect reads by its document element,
TML's ``<mission>``; a dialect's nodes mapped onto the catalog, Aerostack2's: the readers' groups of
:mod:`aeroexec.trees.formats`), ``.yaml``/``.yml`` (the nested form, or a dialect's form by its top-level key,
Aerostack's ``nodes:`` list, :mod:`aeroexec.trees.loaders.yaml_loader`) and the mission-item files
(:mod:`aeroexec.trees.items`), placed from ``home`` (the world's home point; default: the mission's own). Every
problem, whatever the format, is raised as one :class:`~aeroexec.trees.model.TreeFormatError` listing
``(file, line, message)`` (a mission-item file's problems are on its :class:`~aeroexec.trees.items.PlanDocument`,
each with its item number).
"""

from __future__ import annotations

from pathlib import Path

from aeroexec.drones.geodesy import Geodetic
from aeroexec.trees.formats import TREE_MAPPINGS, XML_DOCUMENTS, MissionFormat, expected, format_of, readers
from aeroexec.trees.model import TreeDocument, TreeFormatError

from aeroexec.limits import InputError, decode, read_bytes

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

def load_mission_tree(path: str | Path, home: Geodetic | None = None) -> TreeDocument:
    """The behavior-tree mission in ``path``, read by its format (:func:`~aeroexec.trees.formats.format_of`)."""
    _tree_format(str(path), None)  # an unknown suffix is said before the file is opened
    try:
        data = read_bytes(path)
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return read_mission_tree(data, str(path), home)


def read_mission_tree(text: str | bytes, file: str, home: Geodetic | None = None) -> TreeDocument:
    """A mission from text; ``file`` (its suffix, and for a shared suffix the text, choose the format) names it."""
    fmt = _tree_format(file, text)
    if fmt.items:
        from aeroexec.trees.items.behaviors import items_document
        from aeroexec.trees.items.readers import read_item_mission

        return items_document(read_item_mission(text, file), home)
    return fmt.reader()(text, file, home)


def _tree_format(file: str, text: str | bytes | None) -> MissionFormat:
    fmt = format_of(file, text)
    if fmt is None or not fmt.tree:
        suffix = Path(file).suffix.lower()
        what = f"a {fmt.name[:-1] if fmt.name.endswith('s') else fmt.name} file is not a behavior tree" if fmt \
            else f"unknown mission file type {suffix or '(no extension)'}"
        raise TreeFormatError([(file, 0, f"{what}: {expected(tree=True)}")])
    return fmt


def text_of(data: str | bytes, file: str) -> str:
    """UTF-8 text of a file's bytes; a byte that is not UTF-8 is a :class:`TreeFormatError` with its line."""
    if isinstance(data, str):
        return data
    try:
        return decode(data, file)
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None


# The built-in formats' readers, recognisers and writers, as the table (trees/formats.py) names them.

def read_xml_tree(data: str | bytes, file: str, home: Geodetic | None = None) -> TreeDocument:
    """BehaviorTree.CPP v4 XML, or a document a dialect reads by its document element (TML's ``<mission>``); the
    dialects' nodes mapped onto the catalog (Aerostack2's)."""
    from aeroexec.trees.loaders.xml_loader import parse_xml, read_xml

    raw = data.encode("utf-8") if isinstance(data, str) else data
    lenient: list[tuple[str, int, str]] = []
    root = parse_xml(raw, file, lenient)  # as BehaviorTree.CPP reads it (a raw < in an attribute)
    document = next((found for _, read in sorted(readers(XML_DOCUMENTS).items())
                     if (found := read(root, raw, file, lenient)) is not None), None)
    if document is None:
        document = read_xml(raw, file)
    for _, mapping in sorted(readers(TREE_MAPPINGS).items()):
        document = mapping(document, home)
    return document


def read_yaml_tree(data: str | bytes, file: str, home: Geodetic | None = None) -> TreeDocument:
    """A behavior tree in YAML: the nested form or a dialect's form (Aerostack's ``nodes:`` list)."""
    from aeroexec.trees.loaders.yaml_loader import read_yaml

    return read_yaml(text_of(data, file), file)


def is_legacy_mission(text: str) -> bool:
    """A ``.mission`` of QGroundControl's legacy JSON, not QGC WPL as PX4's own tests write it."""
    from aeroexec.trees.items.wpl import is_wpl

    return not is_wpl(text)


def write_xml_tree(tree: TreeDocument, catalog: Any, home: Geodetic | None = None) -> str:
    from aeroexec.trees.loaders.xml_writer import write_xml

    return write_xml(tree, catalog)


def write_plan_file(tree: TreeDocument, catalog: Any, home: Geodetic) -> str:
    from aeroexec.trees.items.writer import write_plan

    return write_plan(tree, home)


def write_waypoints_file(tree: TreeDocument, catalog: Any, home: Geodetic) -> str:
    from aeroexec.trees.items.writer import write_waypoints

    return write_waypoints(tree, home)
