"""Test-wide settings: ``--fuzz-budget SECONDS`` (the time the fuzz tests spend on each input format), and a
per-test runtime directory where runs list themselves (never the user's)."""

from __future__ import annotations

import pytest

#: Seconds of fuzzing per format in a default run: enough to catch a regression, short enough for every run.
DEFAULT_FUZZ_BUDGET = 2.0


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--fuzz-budget", type=float, default=DEFAULT_FUZZ_BUDGET, metavar="SECONDS",
                     help=f"seconds of fuzzing per input format in tests/fuzz (default {DEFAULT_FUZZ_BUDGET:g}); "
                          "bench/fuzz.py runs for minutes and prints the table")


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
