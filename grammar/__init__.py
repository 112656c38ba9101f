"""The grammars, shipped as package data: the belief language (`beliefs.lark`) and BehaviorTree.CPP's scripts
(`script.lark`); :func:`lalr_parser` (``lalr.py``) builds a Lark parser for one of them, cached in the user's private
cache folder.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from typing import TYPE_CHECKING

from aeroexec.lazy import lazy_names

__all__ = ["lalr_parser"]
__getattr__ = lazy_names(__name__, {"lalr_parser": "lalr"})

if TYPE_CHECKING:
    from aeroexec.grammar.lalr import lalr_parser
