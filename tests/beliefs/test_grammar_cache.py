"""The grammars' parsers come from the user's private cache folder (Lark's cache is a pickle: never a shared one)."""

from __future__ import annotations

import os

from aeroexec.grammar import lalr_parser


def test_a_parser_is_cached_in_the_private_folder_and_loaded_from_it(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    first = lalr_parser("script.lark")
    folder = tmp_path / "aeroexec"
    [cache] = folder.iterdir()
    assert cache.name.startswith("script.lark.") and folder.stat().st_mode & 0o777 == 0o700
    written = cache.stat().st_mtime_ns
    again = lalr_parser("script.lark")  # loaded from the file, which is not written again
    assert again.parse("x := 1 + 2") == first.parse("x := 1 + 2") and cache.stat().st_mtime_ns == written


def test_one_grammar_with_other_options_has_a_file_of_its_own(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    lalr_parser("beliefs.lark", maybe_placeholders=True)
    rules = lalr_parser("beliefs.lark", start="program", propagate_positions=True, maybe_placeholders=True)
    assert len(list((tmp_path / "aeroexec").iterdir())) == 2
    again = lalr_parser("beliefs.lark", start="program", propagate_positions=True, maybe_placeholders=True)
    assert again.parse("safe(?X) :- clear(?X).\n") == rules.parse("safe(?X) :- clear(?X).\n")


def test_a_torn_cache_file_is_built_again_and_rewritten(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    lalr_parser("script.lark")
    [cache] = (tmp_path / "aeroexec").iterdir()
    whole = cache.read_bytes()
    cache.write_bytes(whole[: len(whole) // 2])  # as another process leaves it while it writes
    parser = lalr_parser("script.lark")
    assert parser.parse("x := 1") is not None and cache.read_bytes() != whole[: len(whole) // 2]
    written = cache.stat().st_mtime_ns  # written whole again: the next parser is loaded from it
    assert lalr_parser("script.lark").parse("x := 1") is not None and cache.stat().st_mtime_ns == written


def test_a_cache_folder_others_may_write_is_not_used(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    (tmp_path / "aeroexec").mkdir()
    os.chmod(tmp_path / "aeroexec", 0o777)  # someone could plant a pickle there
    parser = lalr_parser("script.lark")
    assert parser.parse("x := 1") is not None and not list((tmp_path / "aeroexec").iterdir())
