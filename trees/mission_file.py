"""Reading a behavior-tree mission file of any supported kind: the format is chosen by the file's extension.

``load_mission_tree(path)`` reads ``.xml`` (BehaviorTree.CPP v4, :mod:`aeroexec.trees.loaders.xml_loader`, or a TML
mission when the document element is ``<mission>``, :mod:`aeroexec.trees.tml.compiler`; Aerostack2's behavior-tree
nodes are mapped onto the catalog, :mod:`aeroexec.trees.loaders.aerostack2_nodes`), ``.yaml``/``.yml`` (the nested
form or Aerostack's ``nodes:`` list, :mod:`aeroexec.trees.loaders.yaml_loader`), Aerostack2's interpreter missions in
``.json``, ``.yaml`` or ``.yml`` (``{target, plan}``, :mod:`aeroexec.trees.loaders.aerostack2_loader`) and the
mission-item files (:mod:`aeroexec.trees.items`): ``.plan`` and ``.mission`` (QGroundControl), ``.waypoints`` and
``.txt`` (QGC WPL 110), placed from ``home`` (the world's home point; default: the mission's own) into a
:class:`~aeroexec.trees.model.TreeDocument`. Every problem, whatever the format, is raised as one
:class:`~aeroexec.trees.model.TreeFormatError` listing ``(file, line, message)`` (a mission-item file's
problems are on its :class:`~aeroexec.trees.items.PlanDocument`, each with its item number).
"""

from __future__ import annotations

from pathlib import Path

from aeroexec.drones.geodesy import Geodetic
from aeroexec.trees.items.readers import ITEM_EXTENSIONS
from aeroexec.trees.model import TreeDocument, TreeFormatError

from aeroexec.limits import InputError, read_text

# Each format's reader is imported when a file of that format is read: one command reads one kind of file (the XML
# reader alone pulls in the SAX parser and urllib; the mission items, the simulator's geofences).

MISSION_EXTENSIONS = (".xml", ".yaml", ".yml", ".json", *ITEM_EXTENSIONS)
_EXPECTED = "expected .xml, .yaml, .yml, .json, .plan, .mission, .waypoints or .txt"


def load_mission_tree(path: str | Path, home: Geodetic | None = None) -> TreeDocument:
    """The behavior-tree mission in ``path`` (see the module's docstring for the extensions)."""
    suffix = Path(path).suffix.lower()
    if suffix in ITEM_EXTENSIONS:
        from aeroexec.trees.items.behaviors import items_document
        from aeroexec.trees.items.readers import load_item_mission

        return items_document(load_item_mission(path), home)
    if suffix == ".xml":
        from aeroexec.trees.loaders.aerostack2_nodes import aerostack2_tree
        from aeroexec.trees.tml.compiler import load_xml_mission

        return aerostack2_tree(load_xml_mission(path), home)
    if suffix in (".yaml", ".yml", ".json"):
        try:
            text = read_text(path)
        except InputError as exc:
            raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
        return read_mission_tree(text, str(path), home)
    raise TreeFormatError([(str(path), 0, f"unknown mission file type {suffix or '(no extension)'}: {_EXPECTED}")])


def read_mission_tree(text: str | bytes, file: str, home: Geodetic | None = None) -> TreeDocument:
    """A mission from text; ``file`` (its extension chooses the format) names it in problems."""
    suffix = Path(file).suffix.lower()
    if suffix in ITEM_EXTENSIONS:
        from aeroexec.trees.items.behaviors import items_document
        from aeroexec.trees.items.readers import read_item_mission

        return items_document(read_item_mission(text, file), home)
    if suffix == ".xml":
        from aeroexec.trees.loaders.aerostack2_nodes import aerostack2_tree
        from aeroexec.trees.tml.compiler import read_xml_mission

        return aerostack2_tree(read_xml_mission(text, file), home)
    if suffix in (".yaml", ".yml", ".json"):
        try:
            text = text.decode("utf-8") if isinstance(text, bytes) else text
        except UnicodeDecodeError as exc:
            raise TreeFormatError([(file, 0, f"cannot read the file: {exc}")]) from None
        from aeroexec.trees.loaders.aerostack2_loader import is_aerostack2_plan, read_aerostack2_plan

        if suffix == ".json" or is_aerostack2_plan(text):
            return read_aerostack2_plan(text, file, home)
        from aeroexec.trees.loaders.yaml_loader import read_yaml

        return read_yaml(text, file)
    raise TreeFormatError([(file, 0, f"unknown mission file type {suffix or '(no extension)'}: {_EXPECTED}")])
