"""A catalog read without errors is kept parsed in the user's private cache folder: the next start of a command
loads it from there, a changed file is read again, a broken one still errors at its line, warnings still show."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import pytest
from aeroexec.engine.catalog import default_catalog_path, load_catalog
from aeroexec.engine.errors import CatalogError

DATA = Path(__file__).parent / "data"


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "aeroexec"


def kept(cache: Path) -> list[Path]:
    return sorted(cache.glob("catalog.*.pickle")) if cache.exists() else []


def test_a_catalog_is_loaded_from_the_cache_the_second_time(cache, tmp_path):
    path = tmp_path / "aerial.yaml"
    shutil.copy(default_catalog_path(), path)
    first = load_catalog(path)
    [file] = kept(cache)
    written = file.stat().st_mtime_ns
    again = load_catalog(path)
    assert file.stat().st_mtime_ns == written and kept(cache) == [file]
    assert sorted(again.behaviors) == sorted(first.behaviors) and again.source == first.source
    assert again.behaviors["GO_TO_POINT"] == first.behaviors["GO_TO_POINT"]
    assert again.incompatible("GO_TO_POINT", "KEEP_HOVERING") == first.incompatible("GO_TO_POINT", "KEEP_HOVERING")


def test_a_changed_catalog_file_is_read_again(cache, tmp_path):
    path = tmp_path / "aerial.yaml"
    text = default_catalog_path().read_text()
    path.write_text(text)
    old = "Land vertically where the robot is.\n  timeout: 90\n"
    assert old in text and load_catalog(path).behavior("LAND").timeout == 90
    path.write_text(text.replace(old, old.replace("90", "77")))
    assert load_catalog(path).behavior("LAND").timeout == 77
    assert len(kept(cache)) == 2


def test_a_broken_catalog_still_errors_at_its_line_after_a_good_one_was_kept(cache, tmp_path):
    path = tmp_path / "catalog.yaml"
    shutil.copy(default_catalog_path(), path)
    load_catalog(path)
    lines = path.read_text().splitlines(keepends=True)
    at = next(i for i, line in enumerate(lines) if line.strip() == "- behavior: LAND")
    lines.insert(at + 1, "  category: sometimes\n")
    path.write_text("".join(lines))
    for _ in range(2):  # never kept: the second load finds the error again
        with pytest.raises(CatalogError) as info:
            load_catalog(path)
        assert any(f"{path}:{at + 2}: error" in str(p) for p in info.value.errors), info.value.errors
    assert len(kept(cache)) == 1


def test_a_cached_catalog_still_shows_its_warnings(cache, caplog):
    paper = load_catalog(DATA / "appendix_b.yaml")
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="aeroexec.engine.catalog"):
        again = load_catalog(DATA / "appendix_b.yaml")
    assert len(kept(cache)) == 1
    assert [str(w) for w in again.warnings] == [str(w) for w in paper.warnings]
    assert any("START_MOVING" in r.getMessage() and ":126:" in r.getMessage() for r in caplog.records)


def test_other_processes_are_another_entry(cache):
    load_catalog(DATA / "appendix_b.yaml")
    narrow = load_catalog(DATA / "appendix_b.yaml", processes={"droneTrajectoryController"})
    assert any("PATH_PLANNING is not supported by the architecture" in str(w) for w in narrow.warnings)
    assert len(kept(cache)) == 2


def test_a_torn_cache_file_is_parsed_again(cache, tmp_path):
    path = tmp_path / "aerial.yaml"
    shutil.copy(default_catalog_path(), path)
    load_catalog(path)
    [file] = kept(cache)
    file.write_bytes(file.read_bytes()[:100])
    assert "GO_TO_POINT" in load_catalog(path) and len(file.read_bytes()) > 100


def test_without_a_writable_cache_folder_the_catalog_is_read_every_time(tmp_path, monkeypatch):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    assert "GO_TO_POINT" in load_catalog(default_catalog_path())
    assert "GO_TO_POINT" in load_catalog(default_catalog_path())


def test_the_cache_keeps_only_the_newest_catalogs(cache, tmp_path, monkeypatch):
    import aeroexec.engine.catalog.behavior_catalog as behavior_catalog

    monkeypatch.setattr(behavior_catalog, "KEPT_CATALOGS", 2)
    text = default_catalog_path().read_text()
    path = tmp_path / "aerial.yaml"
    for timeout in (91, 92, 93):  # three versions of the file, each kept when read
        path.write_text(text.replace("Land vertically where the robot is.\n  timeout: 90\n",
                                     f"Land vertically where the robot is.\n  timeout: {timeout}\n"))
        assert load_catalog(path).behavior("LAND").timeout == timeout
    assert len(kept(cache)) == 2
    assert load_catalog(path).behavior("LAND").timeout == 93
