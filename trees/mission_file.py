"""Reading a behavior-tree mission file of any supported kind: the format is chosen by the file's extension.

``load_mission_tree(path)`` reads ``.xml`` (BehaviorTree.CPP v4, :mod:`aeroexec.trees.loaders.xml_loader`, or a TML
mission when the document element is ``<mission>``, :mod:`aeroexec.trees.tml.compiler`), ``.yaml``/``.yml`` (the
nested form or Aerostack's ``nodes:`` list, :mod:`aeroexec.trees.loaders.yaml_loader`) and the mission-item files
(:mod:`aeroexec.trees.items`): ``.plan`` and ``.mission`` (QGroundControl), ``.waypoints`` and ``.txt``
(QGC WPL 110), placed from ``home`` (the world's home point; default: the mission's own) into a
:class:`~aeroexec.trees.model.TreeDocument`. Every problem, whatever the format, is raised as one
:class:`~aeroexec.trees.model.TreeFormatError` listing ``(file, line, message)`` (a mission-item file's
problems are on its :class:`~aeroexec.trees.items.PlanDocument`, each with its item number).
"""

from __future__ import annotations

from pathlib import Path

from aeroexec.drones.geodesy import Geodetic
from aeroexec.trees.items import ITEM_EXTENSIONS, items_document, read_item_mission
from aeroexec.trees.items.readers import load_item_mission
from aeroexec.trees.loaders.yaml_loader import load_yaml, read_yaml
from aeroexec.trees.model import TreeDocument, TreeFormatError
from aeroexec.trees.tml.compiler import load_xml_mission, read_xml_mission

MISSION_EXTENSIONS = (".xml", ".yaml", ".yml", *ITEM_EXTENSIONS)
_EXPECTED = "expected .xml, .yaml, .yml, .plan, .mission, .waypoints or .txt"


def load_mission_tree(path: str | Path, home: Geodetic | None = None) -> TreeDocument:
    """The behavior-tree mission in ``path`` (see the module's docstring for the extensions)."""
    suffix = Path(path).suffix.lower()
    if suffix in ITEM_EXTENSIONS:
        return items_document(load_item_mission(path), home)
    if suffix == ".xml":
        return load_xml_mission(path)
    if suffix in (".yaml", ".yml"):
        return load_yaml(path)
    raise TreeFormatError([(str(path), 0, f"unknown mission file type {suffix or '(no extension)'}: {_EXPECTED}")])


def read_mission_tree(text: str | bytes, file: str, home: Geodetic | None = None) -> TreeDocument:
    """A mission from text; ``file`` (its extension chooses the format) names it in problems."""
    suffix = Path(file).suffix.lower()
    if suffix in ITEM_EXTENSIONS:
        return items_document(read_item_mission(text, file), home)
    if suffix == ".xml":
        return read_xml_mission(text, file)
    if suffix in (".yaml", ".yml"):
        try:
            return read_yaml(text.decode("utf-8") if isinstance(text, bytes) else text, file)
        except UnicodeDecodeError as exc:
            raise TreeFormatError([(file, 0, f"cannot read the file: {exc}")]) from None
    raise TreeFormatError([(file, 0, f"unknown mission file type {suffix or '(no extension)'}: {_EXPECTED}")])
