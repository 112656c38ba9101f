"""The page the belief and rule benches write their tables into: docs/performance/beliefs-and-rules.md, each table
between the marks ``<!-- bench/NAME: start -->`` and ``<!-- bench/NAME: end -->``."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

PAGE = Path(__file__).resolve().parents[1] / "docs" / "performance" / "beliefs-and-rules.md"


def write_section(bench: str, text: str) -> None:
    """Put ``text`` between the marks of ``bench`` (e.g. ``bench/rules.py``) in the page."""
    start_mark, end_mark = f"<!-- {bench}: start -->", f"<!-- {bench}: end -->"
    page = PAGE.read_text()
    start, end = page.index(start_mark) + len(start_mark), page.index(end_mark)
    PAGE.write_text(page[:start] + "\n" + text + "\n" + page[end:])
    print(f"wrote the table into {PAGE}")


def swi_version() -> str:
    """The version of the ``swipl`` on the path (the baseline a table names)."""
    swipl = shutil.which("swipl")
    if swipl is None:
        return "(not installed)"
    done = subprocess.run([swipl, "--version"], capture_output=True, text=True)
    found = re.search(r"version (\S+)", done.stdout)
    return found.group(1) if found else "?"
