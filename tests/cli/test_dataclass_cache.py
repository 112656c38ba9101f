"""The methods ``@dataclass`` writes are compiled once and kept in the user's cache folder (aeroexec/dataclass_cache.py,
issue 45): the next command of the same sub-command compiles none of them, and the classes are the ones
:mod:`dataclasses` builds without it."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


def python(code: str, cache: Path) -> str:
    """What a fresh interpreter running ``code`` prints, with ``cache`` as its user's cache folder."""
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, cwd="/",
                          env={**os.environ, "XDG_CACHE_HOME": str(cache)})
    assert done.returncode == 0, done.stderr
    return done.stdout


VERIFY = f"""
    import contextlib, io, sys
    sys.argv = ["aeroexec", "verify", {str(MISSIONS / "figure10.xml")!r}]
    from aeroexec import dataclass_cache
    from aeroexec.cli.main import main
    shown = io.StringIO()
    with contextlib.redirect_stdout(shown):
        status = main()
    print(status, shown.getvalue().strip())
    print("compiled", dataclass_cache._kept.compiled)
"""


def test_a_second_verify_compiles_no_dataclass_method_and_says_the_same(tmp_path):
    first = python(VERIFY, tmp_path).splitlines()
    kept = list((tmp_path / "aeroexec").glob("dataclass-code.verify.*.marshal"))
    assert len(kept) == 1
    again = python(VERIFY, tmp_path).splitlines()
    assert first[0] == again[0] and first[0].startswith("0 ") and "0 errors" in first[0]
    assert int(first[1].split()[1]) > 40  # the catalog's descriptors, the world's records, the tree's nodes...
    assert again[1] == "compiled 0"


def waypoint(extra: str = "", kept: bool = True) -> str:
    """A script building a frozen dataclass (``extra`` one more field line), through the kept code when ``kept``, and
    printing what it shows, then how many sources it compiled."""
    return f"""
import dataclasses
from dataclasses import dataclass, field
from aeroexec import dataclass_cache
if {kept}:
    dataclass_cache.install("test")

@dataclass(frozen=True)
class Waypoint:
    name: str
    altitude: float = 10.0
    tags: list = field(default_factory=list, compare=False)
    {extra}

here = Waypoint("home", tags=["a"])
print(here, here == Waypoint("home"), hash(here) == hash(Waypoint("home")), dataclasses.fields(here)[-1].name)
try:
    here.altitude = 3.0
except dataclasses.FrozenInstanceError as error:
    print("frozen:", error)
print(dataclass_cache._kept.compiled)
"""


def built(tmp_path: Path, extra: str = "", kept: bool = True) -> tuple[list[str], int]:
    """What the class :func:`waypoint` builds shows in a fresh interpreter, and how many sources it compiled."""
    shown = python(waypoint(extra, kept), tmp_path).splitlines()
    return shown[:-1], int(shown[-1])


def test_a_class_built_from_kept_code_is_the_class_dataclasses_builds(tmp_path):
    plain, _ = built(tmp_path / "elsewhere", kept=False)
    fresh, compiled = built(tmp_path)
    assert compiled > 0 and list((tmp_path / "aeroexec").glob("dataclass-code.test.*.marshal"))
    again, compiled_again = built(tmp_path)
    assert compiled_again == 0
    assert fresh == again == plain == [
        "Waypoint(name='home', altitude=10.0, tags=['a']) True True tags",
        "frozen: cannot assign to field 'altitude'"]


def test_a_class_whose_fields_changed_is_compiled_again(tmp_path):
    built(tmp_path)
    changed, compiled = built(tmp_path, extra="speed: float = 2.0")
    assert compiled > 0  # its __init__, __repr__, __eq__... are other texts
    assert changed[0] == "Waypoint(name='home', altitude=10.0, tags=['a'], speed=2.0) True True speed"
    _, compiled = built(tmp_path, extra="speed: float = 2.0")
    assert compiled == 0


def test_a_damaged_file_is_compiled_again_and_written_anew(tmp_path):
    built(tmp_path)
    (kept,) = (tmp_path / "aeroexec").glob("dataclass-code.test.*.marshal")
    kept.write_bytes(kept.read_bytes()[:100])
    shown, compiled = built(tmp_path)
    assert compiled > 0 and shown[0].startswith("Waypoint(name='home'")
    _, compiled = built(tmp_path)
    assert compiled == 0


def test_a_cache_folder_others_can_write_is_not_read_nor_written(tmp_path):
    (tmp_path / "aeroexec").mkdir(mode=0o777)
    (tmp_path / "aeroexec").chmod(0o777)
    shown, compiled = built(tmp_path)
    assert compiled > 0 and shown[0].startswith("Waypoint(name='home'")
    assert list((tmp_path / "aeroexec").iterdir()) == []
