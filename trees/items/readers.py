"""Which mission-item reader a file needs, as the table of mission formats says (:mod:`aeroexec.trees.formats`):
``.plan`` is QGroundControl's plan; ``.waypoints`` and ``.txt`` are QGC WPL 110; ``.mission`` is either, by its
first line (QGroundControl's legacy JSON, or WPL as PX4's own tests write it). Files are read through
:mod:`aeroexec.limits` (size bound, UTF-8 with the line of a bad byte)."""

from __future__ import annotations

from pathlib import Path

from aeroexec.trees.formats import format_of, formats

from aeroexec.limits import InputError, decode, read_bytes

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from aeroexec.trees.items.model import ItemMission

def is_item_file(path: str | Path, text: str | bytes | None = None) -> bool:
    """Whether ``path`` is a mission-item file (a format of the table with ``items``)."""
    fmt = format_of(path, text)
    return fmt is not None and fmt.items


def read_item_mission(text: str | bytes, file: str) -> ItemMission:
    """The item mission in ``text`` (``file`` names it; its suffix, and for ``.mission`` the text, choose the
    reader)."""
    from aeroexec.trees.model import TreeFormatError  # here: a mission in local meters needs no tree model

    fmt = format_of(file, text)
    if fmt is None or not fmt.items:
        known = ", ".join(s for f in formats() if f.items for s in f.suffixes)
        raise TreeFormatError([(file, 0, f"not a mission-item file: expected one of {known}")])
    if isinstance(text, bytes):
        try:
            text = decode(text, file)
        except InputError as exc:
            raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return fmt.reader()(text, file)


def load_item_mission(path: str | Path) -> ItemMission:
    """The item mission in the file ``path``."""
    from aeroexec.trees.model import TreeFormatError

    try:
        data = read_bytes(path, what="the mission")
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return read_item_mission(data, str(path))
