"""Packaging by use (issue 35, point 1): ``pip install aeroexec`` flies a mission; fleets, the web console, the
report's images and Groot2 live are extras, each refused with the exact ``pip install`` line when missing.

A missing extra is simulated in a subprocess by setting its modules to None in ``sys.modules`` (``import`` then
fails as for a module that is not installed); the real check, a fresh virtual environment with ``pip install .``,
is in the README and was run by hand."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from aeroexec import extras
from aeroexec.extras import EXTRAS, MissingExtra, install_line, require

ROOT = Path(__file__).parents[2]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
EVERY_MODULE = sorted(m for extra in EXTRAS.values() for m in extra.modules)

BLOCKED = """import sys
for name in sys.argv[1].split(","):
    sys.modules[name] = None  # as if not installed
from aeroexec.cli.main import main
sys.exit(main(sys.argv[2:]))
"""


def without(modules: list[str], *argv: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    """``aeroexec ARGV`` with ``modules`` not importable."""
    return subprocess.run([sys.executable, "-c", BLOCKED, ",".join(modules), *argv], cwd=cwd, capture_output=True,
                          text=True, timeout=120)


def _name(requirement: str) -> str:
    return requirement.split(";")[0].split("[")[0].split("=")[0].split(">")[0].split("<")[0].strip().lower()


def test_the_extras_of_pyproject_are_the_ones_the_code_names():
    optional = PROJECT["optional-dependencies"]
    for name, extra in EXTRAS.items():
        assert sorted(_name(r) for r in optional[name]) == sorted(d.lower() for d in extra.modules.values())
    assert optional["all"] == [f"aeroexec[{','.join(EXTRAS)}]"]
    assert "aeroexec[all]" in optional["test"]
    core = {_name(r) for r in PROJECT["dependencies"]}
    assert {"py_trees", "lark", "pyyaml", "mavsdk"} <= core  # the user's chosen core
    assert not core & {d.lower() for extra in EXTRAS.values() for d in extra.modules.values()}


def test_a_mission_flies_with_no_extra_installed(tmp_path):
    result = without(EVERY_MODULE, "run", "missions/figure10.py", "--plain", "--output", str(tmp_path / "out"))
    assert result.returncode == 0, result.stderr
    assert "figure10.py: completed" in result.stderr
    tree = without(EVERY_MODULE, "run", "missions/figure10.xml", "--quiet", "--output", str(tmp_path / "tree"))
    assert tree.returncode == 0, tree.stderr
    assert (tmp_path / "tree" / "mission.btlog").is_file()
    checked = without(EVERY_MODULE, "verify", "missions/iarc7.xml", "missions/survey.plan")
    assert checked.returncode == 0, checked.stderr
    answered = without(EVERY_MODULE, "beliefs", str(tmp_path / "out"), "-q", "flight_state(self, ?S)")
    assert answered.returncode == 0 and "landed" in answered.stdout, answered.stderr


@pytest.mark.parametrize(("argv", "extra"), [
    (["fleet", "missions/relay.yaml", "--plain"], "fleet"),
    (["run", "missions/figure10.py", "--fleet", "f", "--name", "d1"], "fleet"),
    (["ctl", "--fleet", "f", "status"], "fleet"),
    (["run", "missions/figure10.py", "--web"], "console"),
    (["console", "missions"], "console"),
    (["run", "missions/figure10.xml", "--groot"], "groot"),
    (["report", "missing/events.jsonl"], "report"),
    (["export", "missing", "--mcap", "missing.mcap"], "ros"),
    (["run", "missions/figure10.xml", "--mcap", "flight.mcap"], "ros"),
    (["run", "missions/figure10.xml", "--foxglove"], "foxglove"),
])
def test_a_missing_extra_is_refused_before_anything_runs_with_the_pip_line(argv, extra, tmp_path):
    result = without(list(EXTRAS[extra].modules), *argv, "--output", str(tmp_path / "out")) \
        if argv[0] in ("run", "fleet") else without(list(EXTRAS[extra].modules), *argv)
    assert result.returncode == 2
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"aeroexec {argv[0]}: ") and f"aeroexec's {extra} extra" in lines[0]
    assert lines[0].endswith(f"pip install -e '.[{extra}]'")  # this checkout is installed editable
    assert not (tmp_path / "out").exists(), "nothing flew"


def test_an_embedder_importing_a_part_without_its_extra_gets_the_pip_line():
    code = ("import sys\nsys.modules['uvicorn'] = None\n"
            "try:\n    import aeroexec.console.server\nexcept ImportError as e:\n"
            "    print(type(e).__name__, e)\n")
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert result.stdout.startswith("MissingExtra the web console and its replays need aeroexec's console extra "
                                    "(uvicorn is not installed): pip install"), result.stdout + result.stderr


def test_a_missing_dependency_of_an_extra_is_reported_as_that_extra():
    with pytest.raises(MissingExtra) as refused, require("report"):
        import aeroexec_no_such_module  # noqa: F401
    assert refused.value.extra == "report" and refused.value.missing == ["aeroexec_no_such_module"]


class _Distribution:
    def __init__(self, direct_url):
        self.direct_url = direct_url

    def read_text(self, name):
        return json.dumps(self.direct_url) if self.direct_url is not None else None


@pytest.mark.parametrize(("direct_url", "line"), [
    (None, "pip install 'aeroexec[fleet]'"),  # from an index
    ({"url": "https://example.org/aeroexec-0.2.0.tar.gz", "archive_info": {}}, "pip install 'aeroexec[fleet]'"),
    ({"url": "file:///opt/src/aeroexec", "dir_info": {}}, "pip install 'aeroexec[fleet]'"),  # another folder:
    ({"url": "file:///opt/src/aeroexec", "dir_info": {"editable": True}}, "pip install 'aeroexec[fleet]'"),  # not "."
])
def test_the_install_line_follows_how_aeroexec_was_installed(monkeypatch, direct_url, line):
    """Outside the folder it was installed from, the line names aeroexec: '.[fleet]' would install whatever project
    the user stands in, and a source path may have moved; pip keeps the aeroexec installed and adds the extra."""
    from importlib import metadata

    monkeypatch.setattr(metadata, "distributions", lambda **select: [_Distribution(direct_url)])
    monkeypatch.chdir("/")
    assert install_line("fleet") == line


def test_a_missing_extra_outside_the_checkout_names_aeroexec_not_the_current_folder(tmp_path):
    result = without(list(EXTRAS["fleet"].modules), "ctl", "--fleet", "f", "status", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip().endswith("pip install 'aeroexec[fleet]'"), result.stderr
    assert "'.[fleet]'" not in result.stderr and str(ROOT) not in result.stderr


def test_the_install_line_names_the_current_folder_as_dot(monkeypatch, tmp_path):
    from importlib import metadata

    monkeypatch.setattr(metadata, "distributions", lambda **select: [_Distribution(
        {"url": tmp_path.as_uri(), "dir_info": {}})])
    monkeypatch.chdir(tmp_path)
    assert install_line("console") == "pip install '.[console]'"
    monkeypatch.setattr(metadata, "distributions", lambda **select: [_Distribution(
        {"url": tmp_path.as_uri(), "dir_info": {"editable": True}})])
    assert install_line("console") == "pip install -e '.[console]'"  # the checkout the user works in
    assert extras.missing("console") == []  # installed here (the suite needs every extra)
