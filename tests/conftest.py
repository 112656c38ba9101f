"""Test-wide settings: ``--fuzz-budget SECONDS`` (the time the fuzz tests spend on each input format),
``--refresh-docs`` (the browser tests write docs/console.png), a
per-test runtime directory where runs list themselves (never the user's), and the browser tests' rule: without
Chromium and its driver they are skipped with the reason, except in CI (``CI=true``), where a skipped browser test
fails the run. A suite started with SIGINT ignored gives its processes Ctrl-C back. The hang guards of waits
(stretched on a loaded machine) are in ``patience.py``, which test modules import (this file cannot be)."""

from __future__ import annotations

import os
import shutil
import signal

import pytest

#: Seconds of fuzzing per format in a default run: enough to catch a regression, short enough for every run.
DEFAULT_FUZZ_BUDGET = 2.0


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--fuzz-budget", type=float, default=DEFAULT_FUZZ_BUDGET, metavar="SECONDS",
                     help=f"seconds of fuzzing per input format in tests/fuzz (default {DEFAULT_FUZZ_BUDGET:g}); "
                          "bench/fuzz.py runs for minutes and prints the table")
    parser.addoption("--refresh-docs", action="store_true",
                     help="write the pictures of the docs the browser tests take (docs/console.png)")


def pytest_configure(config: pytest.Config) -> None:
    """A suite started with SIGINT ignored (a background job of a script, ``nohup``) would hand that on to every
    process it starts, and the tests that press Ctrl-C on a run would wait for an end that never comes: the
    suite's processes take Python's own Ctrl-C back, so theirs have it too."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture
def fuzz_budget(request: pytest.FixtureRequest) -> float:
    return float(request.config.getoption("--fuzz-budget"))


@pytest.fixture(autouse=True)
def private_runtime_dir(tmp_path_factory, monkeypatch):
    """``$XDG_RUNTIME_DIR`` of each test (``aeroexec ctl`` finds live runs there), inherited by subprocesses."""
    path = tmp_path_factory.mktemp("runtime")
    path.chmod(0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(path))
    return path


def browser_missing() -> str | None:
    """Why the browser tests cannot run here (None: Chromium and chromedriver are installed)."""
    absent = [name for name in ("chromium", "chromedriver") if not shutil.which(name)]
    if not absent:
        return None
    return (f"{' and '.join(absent)} not installed: the browser tests need Debian's chromium and chromium-driver "
            f"(apt-get install chromium chromium-driver); CI runs them")


def in_ci() -> bool:
    return os.environ.get("CI", "").lower() in ("true", "1", "yes")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    reason = browser_missing()
    if reason is None or in_ci():  # in CI they run, and fail, rather than pass unseen
        return
    for item in items:
        if item.get_closest_marker("browser"):
            item.add_marker(pytest.mark.skip(reason=reason))


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """In CI a browser test that did not run fails the run: the console must be tested where it can be."""
    if not in_ci():
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    skipped = [r for r in (reporter.stats.get("skipped", []) if reporter else [])
               if "browser" in getattr(r, "keywords", {})]
    if skipped:
        if reporter:
            reporter.write_line(f"CI: {len(skipped)} browser test(s) skipped; CI must run them (install chromium "
                                f"and chromium-driver)", red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED
