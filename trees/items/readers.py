"""Which mission-item reader a file needs: ``.plan`` is QGroundControl's plan; ``.waypoints`` and ``.txt`` are
QGC WPL 110; ``.mission`` is either, by its first line (QGroundControl's legacy JSON, or WPL as PX4's own tests
write it). Files are read through :mod:`aeroexec.limits` (size bound, UTF-8 with the line of a bad byte)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from aeroexec.trees.model import TreeFormatError

from aeroexec.limits import InputError, read_text

if TYPE_CHECKING:
    from aeroexec.trees.items.model import ItemMission

ITEM_EXTENSIONS = (".plan", ".waypoints", ".mission", ".txt")


def is_item_file(path: str | Path) -> bool:
    """Whether ``path`` names a mission-item file by its extension."""
    return Path(path).suffix.lower() in ITEM_EXTENSIONS


def read_item_mission(text: str | bytes, file: str) -> ItemMission:
    """The item mission in ``text`` (``file`` names it and its extension chooses the reader)."""
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError as exc:
            line = text[:exc.start].count(b"\n") + 1
            raise TreeFormatError([(file, line, f"cannot read the file: it is not UTF-8 text ({exc.reason})")]) \
                from None
    # the readers here, not at the top: which files are mission-item files is asked of every mission file
    from aeroexec.trees.items.plan import read_legacy_mission, read_plan
    from aeroexec.trees.items.wpl import is_wpl, read_wpl

    suffix = Path(file).suffix.lower()
    if suffix == ".plan":
        return read_plan(text, file)
    if suffix == ".mission" and not is_wpl(text):
        return read_legacy_mission(text, file)
    return read_wpl(text, file)


def load_item_mission(path: str | Path) -> ItemMission:
    """The item mission in the file ``path``."""
    try:
        text = read_text(path, what="the mission")
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return read_item_mission(text, str(path))
