"""Bad input never escapes: every format's real examples, mutated by hypothesis for ``--fuzz-budget`` seconds each,
end accepted or refused with the project's own errors, each naming its place, within the time limit.

A failing example is saved as a regression file in ``data/<format>/`` (commit it); every file there is replayed.
"""

from __future__ import annotations

import time

import fuzzing
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EDITS = st.lists(st.builds(fuzzing.Edit, st.sampled_from(fuzzing.KINDS), st.integers(0, 65535),
                           st.integers(0, 65535), st.integers(0, len(fuzzing.PAYLOADS) - 1)), min_size=1, max_size=4)


@pytest.mark.parametrize("name", list(fuzzing.FORMATS))
def test_mutated_examples_end_as_placed_errors_never_escapes_or_hangs(name, fuzz_budget, tmp_path):
    fmt = fuzzing.FORMATS[name]
    seeds = [path.read_bytes() for path in fmt.seeds]
    assert seeds, f"no seed files for {name}"
    failures: list[tuple[bytes, fuzzing.Verdict]] = []

    @settings(max_examples=20, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(st.integers(0, len(seeds) - 1), EDITS)
    def one_input(seed: int, edits: list[fuzzing.Edit]) -> None:
        data = fuzzing.apply(seeds[seed], edits)
        verdict = fuzzing.judge(fmt, data, tmp_path)
        if verdict.outcome != "ok":
            failures.append((data, verdict))  # hypothesis replays the shrunk example last
        assert verdict.outcome == "ok", f"{verdict.outcome}: {verdict.detail}"

    end = time.monotonic() + fuzz_budget
    rounds = 0
    while time.monotonic() < end or rounds == 0:
        rounds += 1
        try:
            one_input()
        except AssertionError as error:
            kept = fuzzing.keep(fmt, *failures[-1])
            raise AssertionError(f"{name}: {error}; the input is kept as {kept}") from None


KEPT = sorted(p for p in fuzzing.DATA.glob("*/*") if p.is_file())


@pytest.mark.parametrize("path", KEPT, ids=[f"{p.parent.name}/{p.name}" for p in KEPT])
def test_kept_failures_stay_fixed(path, tmp_path):
    verdict = fuzzing.judge(fuzzing.format_of(path), path.read_bytes(), tmp_path)
    assert verdict.outcome == "ok", f"{verdict.outcome}: {verdict.detail}"


def test_every_format_has_kept_regressions():
    assert {fuzzing.format_of(p).name for p in KEPT} == set(fuzzing.FORMATS)


def test_the_judge_tells_an_escape_a_hang_and_a_lost_place_from_a_placed_error(tmp_path):
    def escapes(path):
        raise KeyError("no such key")

    def hangs(path):
        while True:
            pass

    def loses_its_place(path):
        return [f"{path}: error: something is wrong somewhere"]

    def places(path):
        return [f"{path}:3: error: the value 1e400 is not a finite number"]

    verdicts = {read.__name__: fuzzing.judge(fuzzing.Format("t", ".txt", (), read), b"x", tmp_path, seconds=0.5)
                for read in (escapes, hangs, loses_its_place, places)}
    assert {name: v.outcome for name, v in verdicts.items()} == {
        "escapes": "uncaught", "hangs": "hang", "loses_its_place": "unplaced", "places": "ok"}
    assert verdicts["escapes"].detail == "KeyError: 'no such key'"
    assert verdicts["hangs"].detail == "more than 0.5 s of CPU"


def test_a_reader_slowed_by_a_loaded_machine_is_not_a_hang(tmp_path):
    """The hang limit is the reader's CPU time: waiting on other processes (a loaded CI) does not count. On the wall
    clock a slow, correct reader on a loaded machine was judged a hang ("hang: more than 10 s")."""
    def waits(path):  # off the CPU for twice the limit, as a reader is when the cores are busy elsewhere
        time.sleep(1.0)
        return []

    verdict = fuzzing.judge(fuzzing.Format("t", ".txt", (), waits), b"x", tmp_path, seconds=0.5)
    assert verdict.outcome == "ok", verdict.detail
