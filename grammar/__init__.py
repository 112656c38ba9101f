"""The grammars, shipped as package data: the belief language (`beliefs.lark`) and BehaviorTree.CPP's scripts
(`script.lark`); :func:`lalr_parser` (``lalr.py``) builds a Lark parser for one of them, cached in the user's private
cache folder.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["lalr_parser"]
__getattr__ = lazy_names(__name__, {"lalr_parser": "lalr"})

if TYPE_CHECKING:
    from aeroexec.grammar.lalr import lalr_parser
