"""How the suite itself behaves (issue 35, point 3): it prints its slowest tests, browser tests are skipped with
the reason where Chromium is missing, and in CI (``CI=true``) a browser test that did not run fails the run."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).parents[2]

FAKE = '''import pytest

pytestmark = pytest.mark.browser


def test_in_a_browser():
    assert True
'''


def suite(tmp_path: Path, ci: bool, chromium: bool, test: str = FAKE) -> subprocess.CompletedProcess:
    """The repository's conftest over one browser test, run by pytest in a folder of its own."""
    shutil.copy(ROOT / "tests" / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_page.py").write_text(test)
    (tmp_path / "pytest.ini").write_text("[pytest]\naddopts = -ra\nmarkers =\n    browser: a browser test\n")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(exist_ok=True)
    if chromium:
        for tool in ("chromium", "chromedriver"):
            (bin_dir / tool).write_text("#!/bin/sh\n")
            (bin_dir / tool).chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    env["PATH"] = str(bin_dir)  # only what this test puts there
    if ci:
        env["CI"] = "true"
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)


def test_without_chromium_browser_tests_are_skipped_with_the_reason(tmp_path):
    result = suite(tmp_path, ci=False, chromium=False)
    assert result.returncode == 0, result.stdout
    assert "1 skipped" in result.stdout
    assert "chromium and chromedriver not installed" in result.stdout and "apt-get install chromium" in result.stdout


def test_in_ci_a_browser_test_that_did_not_run_fails_the_run(tmp_path):
    result = suite(tmp_path, ci=True, chromium=False)  # not skipped in CI: it runs (here it passes)...
    assert result.returncode == 0 and "1 passed" in result.stdout, result.stdout
    skipped = suite(tmp_path, ci=True, chromium=True,  # ...and skipped for any reason, it fails the run
                    test=FAKE.replace("assert True", "pytest.skip('no display')"))
    assert skipped.returncode == 1, skipped.stdout
    assert "CI: 1 browser test(s) skipped; CI must run them" in skipped.stdout


def test_the_suite_prints_its_slowest_tests():
    options = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]["addopts"]
    assert "--durations=" in options


def test_hang_guards_stretch_with_the_load_and_in_ci(monkeypatch):
    """A wait for an event fails as hung only after its guard, stretched by the load per core, at least 3x in CI,
    and never more than 10x (a real hang still ends the test); AEROEXEC_TEST_PATIENCE sets the factor."""
    import patience

    monkeypatch.delenv("AEROEXEC_TEST_PATIENCE", raising=False)
    monkeypatch.delenv("CI", raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.5, 0.5, 0.5))
    assert patience.hang_guard(10) == 10  # an idle machine: as written
    monkeypatch.setattr(os, "getloadavg", lambda: (14.0, 12.0, 10.0))
    assert patience.hang_guard(10) == 70  # 7 runnable per core
    monkeypatch.setattr(os, "getloadavg", lambda: (60.0, 60.0, 60.0))
    assert patience.hang_guard(10) == 100
    monkeypatch.setattr(os, "getloadavg", lambda: (0.5, 0.5, 0.5))
    monkeypatch.setenv("CI", "true")
    assert patience.hang_guard(10) == 30
    monkeypatch.setenv("AEROEXEC_TEST_PATIENCE", "5")
    assert patience.hang_guard(10) == 50


CTRL_C = """import signal
import subprocess
import sys


def test_a_run_started_by_the_suite_takes_ctrl_c():
    child = subprocess.run([sys.executable, "-c", "import signal; print(signal.getsignal(signal.SIGINT))"],
                           capture_output=True, text=True)
    assert "default_int_handler" in child.stdout, child.stdout
"""


def test_a_suite_started_with_ctrl_c_ignored_gives_its_runs_ctrl_c(tmp_path):
    """A background job of a script (or nohup) starts with SIGINT ignored and its children inherit that: the
    tests that press Ctrl-C on an ``aeroexec run`` then failed, waiting for an end that never came."""
    shutil.copy(ROOT / "tests" / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_ctrl_c.py").write_text(CTRL_C)
    (tmp_path / "pytest.ini").write_text("[pytest]\naddopts = -ra\nmarkers =\n    browser: a browser test\n")
    result = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q"], cwd=tmp_path,
                            capture_output=True, text=True, timeout=120,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    assert result.returncode == 0, result.stdout
