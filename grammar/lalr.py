"""LALR parsers of the grammars, from a cache in the user's private cache folder.

Building an LALR parser from a grammar costs about 25 ms of CPU (measured by ``bench/startup.py``'s commands), paid
by every command that reads a belief or a script; Lark keeps the analysed grammar in a cache file (a pickle) and
loads it in about 3 ms. The cache lives in the user's own cache folder (``$XDG_CACHE_HOME/aeroexec``, else
``~/.cache/aeroexec``), never in the shared temporary folder: a pickle is loaded only from a folder that belongs to
the user and that nobody else may write. Without such a folder the parser is built every time. Lark checks the
file against the grammar, the options and its own version before it uses it, and builds the parser again (and
writes the file again) when it does not match or cannot be read (one written by another process at that moment).
"""


from __future__ import annotations

import hashlib
import sys
from importlib import resources
from typing import Any

from lark import Lark
from lark import __version__ as lark_version

from aeroexec.cache import user_cache_folder

__all__ = ["lalr_parser"]


def lalr_parser(grammar: str, **options: Any) -> Lark:
    """An LALR parser for the grammar file ``grammar`` (``beliefs.lark``) with Lark's ``options``, from the cache
    when it can be."""
    text = resources.files(__package__).joinpath(grammar).read_text(encoding="utf-8")
    folder = user_cache_folder()
    if folder is None:
        return Lark(text, parser="lalr", **options)
    # one file per grammar and options (a transformer changes nothing cached): two parsers never overwrite each other
    shape = repr(sorted((k, v) for k, v in options.items() if k != "transformer"))
    key = hashlib.sha256(shape.encode()).hexdigest()[:12]
    version = f"lark{lark_version}-py{sys.version_info[0]}{sys.version_info[1]}"
    return Lark(text, parser="lalr", cache=str(folder / f"{grammar}.{key}.{version}.cache"), **options)
