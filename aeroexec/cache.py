"""The user's private aeroexec cache folder (``$XDG_CACHE_HOME/aeroexec``, else ``~/.cache/aeroexec``).

What is kept there is loaded with pickle (the LALR tables of the grammars, parsed catalogs), so a file is read only
from a folder that belongs to the user and that nobody else can write; anywhere else (another owner, a folder others
can write, one that cannot be made) the caller works without a cache.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["user_cache_folder"]


def user_cache_folder() -> Path | None:
    """The user's aeroexec cache folder, made if need be; None when it cannot be made or is not private."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = Path(base) / "aeroexec"
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        info = folder.stat()
    except OSError:
        return None
    if hasattr(os, "getuid") and (info.st_uid != os.getuid() or info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)):
        return None
    return folder
