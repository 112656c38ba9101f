"""docs/adding-a-behavior.md, followed literally: its three files added to a copy of the package's catalog and
to the behavior package's search path give a behavior that verifies, flies and passes the page's own test."""

import re
import sys
from pathlib import Path

import aeroexec.engine.behaviors as behaviors
import pytest
from aeroexec.engine.catalog import behavior_catalog
from aeroexec.engine.catalog.specialist import BehaviorSpecialist
from aeroexec.engine.library import default_library

DOC = Path(__file__).parents[2] / "docs" / "adding-a-behavior.md"


def doc_files():
    """``{path: text}`` of every fenced block of the page that starts with ``# file: PATH``."""
    blocks = re.findall(r"```\w+\n# file: ([^\n(]+?)\s*(?:\([^)]*\))?\n(.*?)```", DOC.read_text(), re.S)
    return {path: text for path, text in blocks}


@pytest.fixture
def added(tmp_path, monkeypatch):
    files = doc_files()
    assert set(files) == {"catalogs/aerial.yaml", "engine/behaviors/ascend.py", "tests/engine/test_ascend.py"}
    catalog = behavior_catalog.default_catalog_path().read_text()
    catalog = catalog.replace("behavior_descriptors:\n", "behavior_descriptors:\n" + files["catalogs/aerial.yaml"], 1)
    catalog, n = re.subn(r"(- list: motion_behaviors\n  behaviors:\n)", r"\1    - ASCEND\n", catalog)
    assert n == 1
    (tmp_path / "aerial.yaml").write_text(catalog)
    (tmp_path / "ascend.py").write_text(files["engine/behaviors/ascend.py"])
    monkeypatch.setattr(behavior_catalog, "default_catalog_path", lambda: tmp_path / "aerial.yaml")
    behavior_catalog.default_catalog.cache_clear()
    monkeypatch.setattr(behaviors, "__path__", [*behaviors.__path__, str(tmp_path)])
    yield files
    behavior_catalog.default_catalog.cache_clear()
    sys.modules.pop("aeroexec.engine.behaviors.ascend", None)


def test_the_page_adds_a_behavior_in_three_files(added):
    assert "ASCEND" in default_library()
    specialist = BehaviorSpecialist()
    assert specialist.request_errors("ASCEND", {"HEIGHT": 3}) == []
    assert specialist.request_errors("ASCEND", {"HEIGHT": 50})  # out of the allowed values
    namespace = {}
    exec(compile(added["tests/engine/test_ascend.py"], "test_ascend.py", "exec"), namespace)
    namespace["test_ascend_climbs_three_meters_above_where_it_started"]()
