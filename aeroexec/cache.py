"""The user's private aeroexec cache folder (``$XDG_CACHE_HOME/aeroexec``, else ``~/.cache/aeroexec``).

What is kept there is loaded with pickle (the LALR tables of the grammars, parsed catalogs and worlds; the behavior
names of the aerial library are text; :func:`kept` and :func:`keep` read and write a file there), so a file is read
only from a folder that belongs to the user and that nobody else can write; anywhere else (another owner, a folder
others can write, one that cannot be made) the caller works without a cache.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

TYPE_CHECKING = False  # typing is not imported at run time
if TYPE_CHECKING:
    from typing import Any

__all__ = ["keep", "kept", "sha256", "unpickled", "user_cache_folder"]


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


def sha256(data: bytes = b"") -> Any:
    """A SHA-256 hash of ``data`` (``update`` adds more) for a cache key: CPython's own implementation when it has one
    (``_sha256``; ``_sha2`` from 3.12), else :mod:`hashlib`'s, which loads OpenSSL (~3 ms of every start that keys a
    kept file). The digests are the same."""
    try:
        from _sha256 import sha256 as made
    except ImportError:
        try:
            from _sha2 import sha256 as made  # type: ignore[no-redef]
        except ImportError:
            from hashlib import sha256 as made  # type: ignore[no-redef]
    return made(data)



def unpickled(data: bytes) -> Any:
    """The object a kept file's ``data`` holds, read by the C unpickler ``pickle.loads`` is: reading needs no more
    (pickle.py, ~1 ms of a start, is imported by what writes a file). Raises what ``pickle.loads`` raises."""
    try:
        from _pickle import loads
    except ImportError:  # an interpreter without the C unpickler
        from pickle import loads
    return loads(data)

def kept(name: str) -> bytes | None:
    """The bytes kept under ``name`` in the user's cache folder; None when there are none (or no private folder)."""
    folder = user_cache_folder()
    if folder is None:
        return None
    try:
        return (folder / name).read_bytes()
    except OSError:
        return None


def keep(name: str, data: bytes, most: int = 16) -> None:
    """Keep ``data`` under ``name`` in the user's cache folder, written atomically (a reader sees the whole file or
    none); of the files named like it (its name up to the first dot), only the ``most`` last written stay. A folder
    that cannot be written is no error: the caller works without the cache."""
    import contextlib
    import tempfile

    folder = user_cache_folder()
    if folder is None:
        return
    prefix = name.split(".", 1)[0] + "."
    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=prefix, suffix=".tmp", delete=False) as file:
            file.write(data)
        os.replace(file.name, folder / name)
    except OSError:
        with contextlib.suppress(OSError, NameError):
            os.unlink(file.name)
        return
    written = []
    for entry in os.scandir(folder):
        if entry.name.startswith(prefix) and not entry.name.endswith(".tmp"):
            with contextlib.suppress(OSError):
                written.append((entry.stat().st_mtime_ns, entry.path))
    for _, path in sorted(written)[:-most]:
        with contextlib.suppress(OSError):
            os.unlink(path)
