"""Reading a Python mission's source within the readers' limits: Python's own parser guarded against inputs that
make it recurse, run out of memory or take quadratic time, every refusal a SyntaxError with a line."""

from __future__ import annotations

import ast
import io
import re
import tokenize
import warnings

from aeroexec.limits import MAX_NESTING

_LONG_DOTTED = re.compile(rf"^[ \t]*(?:import|from)[ \t]+(?:\w+[ \t]*\.[ \t]*){{{MAX_NESTING}}}", re.MULTILINE)
#: The last source parsed, its file name and its AST: a run reads its mission's AST several times (whether it is a
#: script that names drones, its check, whether to run it as a script), and parses it once.
_last: tuple[str, str, ast.Module] | None = None


def parse_source(source: str, filename: str) -> ast.Module:
    """The AST of a mission; SyntaxError (with a line) for invalid Python or nesting beyond ``MAX_NESTING``. The
    same text of the same file gives the same AST object, read once: its readers never change it."""
    global _last
    last = _last
    if last is not None and last[0] == source and last[1] == filename:
        return last[2]
    tree = _parsed(source, filename)
    _last = (source, filename, tree)
    return tree


def _parsed(source: str, filename: str) -> ast.Module:
    dotted = _LONG_DOTTED.search(source)  # Python's parser joins an imported dotted name in quadratic time
    if dotted is not None:
        raise SyntaxError(f"a dotted name of more than {MAX_NESTING} parts",
                          (filename, source.count("\n", 0, dotted.start()) + 1, 0, ""))
    try:
        with warnings.catch_warnings():  # Python's own SyntaxWarnings would print on stderr without our place
            warnings.simplefilter("ignore", SyntaxWarning)
            warnings.simplefilter("ignore", DeprecationWarning)
            tree = ast.parse(source, filename)
    except (RecursionError, MemoryError):  # Python's own parser gives up: name the statement it choked on
        raise SyntaxError(f"an expression is nested too deeply to read (the limit is {MAX_NESTING} levels)",
                          (filename, _longest_statement(source), 0, "")) from None
    stack: list[tuple[ast.AST, int, int, int]] = [(tree, 0, 1, 0)]
    while stack:  # iterative, so that the depth itself is measured without recursion
        node, depth, line, column = stack.pop()
        line, column = getattr(node, "lineno", line), getattr(node, "col_offset", column - 1) + 1
        if depth > MAX_NESTING:
            raise SyntaxError(f"an expression or block is nested more than {MAX_NESTING} levels deep",
                              (filename, line, column, ""))
        stack.extend((child, depth + 1, line, column) for child in ast.iter_child_nodes(node))
    return tree


def _longest_statement(source: str) -> int:
    """The line where the statement with the most tokens starts (where a too-deep expression is)."""
    best, best_line, count, start = 0, 0, 0, 1
    try:
        for token in tokenize.generate_tokens(io.StringIO(source).readline):
            if count == 0:
                start = token.start[0]
            count += 1
            if token.type in (tokenize.NEWLINE, tokenize.ENDMARKER):
                if count > best:
                    best, best_line = count, start
                count = 0
    except (tokenize.TokenError, SyntaxError):
        pass
    return max(best_line, start if count > best else 0, 1)
