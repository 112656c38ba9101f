"""Test-wide settings: runs list themselves in a per-test runtime directory, never the user's."""

import pytest


@pytest.fixture(autouse=True)
def private_runtime_dir(tmp_path_factory, monkeypatch):
    """``$XDG_RUNTIME_DIR`` of each test (``aeroexec ctl`` finds live runs there), inherited by subprocesses."""
    path = tmp_path_factory.mktemp("runtime")
    path.chmod(0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(path))
    return path
